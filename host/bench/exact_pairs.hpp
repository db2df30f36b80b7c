#pragma once
// The exact overlap set on the floats: the benchmark's reference,
// independent of the k-d tree, the keys and the backends.

#include <span>
#include <vector>

#include "core/types.hpp"

namespace bpaccel {

/// Every pair (i < j) of boxes that overlap (inclusively) on all axes, sorted.
/// A uniform grid of cells at least as large as the largest box, each box in
/// the cell of its min corner, so overlapping boxes sit in neighbouring cells:
/// linear in n for scenes of similar boxes. Falls back to sortAndSweepPairs
/// when a coordinate is not finite.
void exactPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);

/// The same set by sort and sweep on x: O(n * boxes overlapping on x).
void sortAndSweepPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);

}  // namespace bpaccel
