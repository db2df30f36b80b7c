#pragma once
// FCL's distance contract from pair finding: candidate pairs in ascending
// order of their AABBs' distance while that stays below the callback's minimum.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <span>
#include <tuple>
#include <vector>

#include <fcl/math/bv/AABB.h>

#include "managed_objects.hpp"
#include "pair_finder.hpp"

namespace bpaccel {

/// Calls visit(i, j, minimum) on pairs of `aabbs` (all, or with `split` > 0
/// only i < split <= j) in ascending order of fcl::AABB::distance, each once
/// and only while that distance lies below `minimum` (which visit lowers),
/// until visit returns true. Every pair closer than the final minimum is
/// visited. Found in passes of a growing radius r: the pairs whose boxes,
/// each grown by r/2, overlap hold every pair within r; a pass visits those
/// at a distance in (previous r, r], and the search ends when the minimum is
/// at or below r. The radius starts at 0 (overlapping boxes), then doubles
/// from the mean spacing until the callback has given a minimum, then is
/// that minimum; it stops growing at the scene's diagonal, where every pair
/// of finite distance is in.
template <typename S>
void visitByDistance(PairFinder& finder, std::span<const fcl::AABB<S>> aabbs, std::size_t split,
                     const std::function<bool(std::uint32_t, std::uint32_t, S&)>& visit) {
  const std::size_t n = aabbs.size();
  if (n < 2 || split >= n) return;
  S diagonal = 0;  // of the finite coordinates' bounds
  for (int a = 0; a < 3; ++a) {
    S lo = std::numeric_limits<S>::max(), hi = std::numeric_limits<S>::lowest();
    for (const auto& b : aabbs) {
      if (std::isfinite(b.min_[a])) lo = std::min(lo, b.min_[a]);
      if (std::isfinite(b.max_[a])) hi = std::max(hi, b.max_[a]);
    }
    if (hi > lo) diagonal += (hi - lo) * (hi - lo);
  }
  diagonal = std::sqrt(diagonal);
  const S spacing = std::max(diagonal / std::cbrt(static_cast<S>(n)), std::numeric_limits<S>::min());
  S minimum = std::numeric_limits<S>::max(), radius = 0, done = -1;
  std::vector<Aabb> grown(n);
  std::vector<std::tuple<S, std::uint32_t, std::uint32_t>> pass;
  for (;;) {
    for (std::size_t k = 0; k < n; ++k) grown[k] = outwardBox(aabbs[k], radius / 2);
    pass.clear();
    for (const Pair& p : finder.find(grown, split)) {
      const S d = aabbs[p.first].distance(aabbs[p.second]);
      if (d > done && d <= radius) pass.emplace_back(d, p.first, p.second);
    }
    std::sort(pass.begin(), pass.end());
    for (const auto& [d, i, j] : pass)
      if (d < minimum && visit(i, j, minimum)) return;
    if (minimum <= radius || radius >= diagonal) return;
    done = radius;
    radius = minimum < std::numeric_limits<S>::max() ? minimum : radius == 0 ? spacing : 2 * radius;
    radius = std::min(radius, diagonal);
  }
}

}  // namespace bpaccel
