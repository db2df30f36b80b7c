#pragma once
// The exact overlap set on the floats: the benchmark's reference,
// independent of the k-d tree, the keys and the backends.

#include <cstdint>
#include <span>
#include <vector>

#include "core/types.hpp"

namespace bpaccel {

/// Every pair (i < j) of boxes that overlap (inclusively) on all axes, sorted.
/// Two ways, whichever tests fewer pairs on this frame (both counted first):
/// a uniform grid of cells at least as large as the largest box, each box in
/// the cell of its min corner, so overlapping boxes sit in neighbouring cells
/// (linear in n for scenes of similar boxes), or a sort and sweep along the
/// axis on which the fewest pairs overlap (scenes of widely spread sizes, or
/// clumps in a large world, where the grid's cells would hold many boxes).
/// Falls back to the sweep when a coordinate is not finite.
void exactPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);

/// The same set by sort and sweep on `axis`: O(n log n + boxes overlapping on that axis).
void sortAndSweepPairs(std::span<const Aabb> boxes, std::vector<Pair>& out, int axis = 0);

/// The number of pairs of boxes whose intervals on `axis` overlap (closed):
/// the interval tests of a sort-and-sweep along that axis. O(n log n).
std::uint64_t pairsOverlappingOn(std::span<const Aabb> boxes, int axis);
/// The same along x.
inline std::uint64_t pairsOverlappingOnX(std::span<const Aabb> boxes) { return pairsOverlappingOn(boxes, 0); }

}  // namespace bpaccel
