#pragma once
// CGAL 5.5's box_self_intersection_d as a benchmark method.

#include <vector>

#include "methods/timed_method.hpp"

namespace bpaccel {

/// CGAL::box_self_intersection_d on closed boxes (boxes that touch overlap,
/// the same rule as Bullet's), run from scratch every frame: the algorithm is
/// batch, with no structure kept between calls. Default cutoff, sequential.
class CgalBoxIntersection final : public TimedMethod {
 public:
  void update(std::span<const Aabb> boxes) override;
  void pairs(std::vector<Pair>& out) override { out = pairs_; }

 private:
  std::vector<Pair> pairs_;
};

std::vector<MethodSpec> cgalMethods();

}  // namespace bpaccel
