#pragma once
// The exact overlap set by sort and sweep on the floats: the benchmark's
// reference, independent of the k-d tree, the keys and the backends.

#include <span>
#include <vector>

#include "types.hpp"

namespace bpaccel {

/// Every pair (i < j) of boxes that overlap (inclusively) on all axes, sorted.
void exactPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);

}  // namespace bpaccel
