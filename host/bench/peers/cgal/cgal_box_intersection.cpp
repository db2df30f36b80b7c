#include "cgal_box_intersection.hpp"

#include <algorithm>

#include <CGAL/box_intersection_d.h>

namespace bpaccel {
namespace {

// The box's address is its id (CGAL's default), so the object index is its offset.
using CgalBox = CGAL::Box_intersection_d::Box_d<float, 3>;

}  // namespace

void CgalBoxIntersection::update(std::span<const Aabb> boxes) {
  // Both the boxes and the pointer sequence are built each frame: the
  // algorithm reorders its input and keeps nothing between calls.
  std::vector<CgalBox> cgalBoxes;
  cgalBoxes.reserve(boxes.size());
  for (const Aabb& b : boxes) {
    float lo[3] = {b.min[0], b.min[1], b.min[2]}, hi[3] = {b.max[0], b.max[1], b.max[2]};
    cgalBoxes.emplace_back(lo, hi);
  }
  std::vector<const CgalBox*> handles(cgalBoxes.size());
  for (std::size_t i = 0; i < cgalBoxes.size(); ++i) handles[i] = &cgalBoxes[i];
  const CgalBox* base = cgalBoxes.data();
  pairs_.clear();
  // Pointers as handles: the documentation's advice when a box is larger than a pointer.
  CGAL::box_self_intersection_d(
      handles.begin(), handles.end(),
      [&](const CgalBox* a, const CgalBox* b) {
        const auto i = static_cast<std::uint32_t>(a - base), j = static_cast<std::uint32_t>(b - base);
        pairs_.emplace_back(std::min(i, j), std::max(i, j));
      },
      std::ptrdiff_t(10), CGAL::Box_intersection_d::CLOSED);
}

std::vector<MethodSpec> cgalMethods() {
  MethodSpec s;
  s.name = "CGAL box_self_intersection_d";
  s.kind = MethodKind::Peer;
  s.library = "CGAL 5.5";
  s.make = [](const SceneStart&) { return std::make_unique<CgalBoxIntersection>(); };
  return {std::move(s)};
}

}  // namespace bpaccel
