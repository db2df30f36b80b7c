#pragma once
// A bounding-volume tree of four children a node, packed bottom-up from the
// boxes in Morton order of their centres: built in linear time every frame.

#include <array>
#include <cstdint>
#include <limits>

#include <immintrin.h>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "ray.hpp"

namespace bpaccel {

/// Each node holds its four children's boxes side by side (a child is a box
/// of the scene or a node below), so one visit tests four boxes at once.
/// Built from the boxes sorted by the Morton code of their centres (a radix
/// sort): the first level groups four consecutive boxes, each level above
/// four consecutive nodes of the one below. A node's box is the exact union
/// of its children's, so it contains every box below it.
///
/// Queries are exact for any input: a ray whose numbers the node tests
/// cannot order (an infinite or zero inverse direction component, an
/// infinite origin or query box, signs that disagree with the inverse
/// direction) is tested against every box instead, with rayMeetsBox. Else
/// the node test is btRayAabb2's on the node's box, in the same float
/// operations: each is monotone in the box, so a node that holds a box the
/// ray meets is met too (docs/queries.md gives the argument).
class BoxTree {
 public:
  /// The tree over boxes[ids[k]] for every k; each id is what the queries report.
  void build(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids);
  std::size_t size() const { return ids_.size(); }
  /// Calls hit(id) for each box of the tree that the ray meets within its
  /// lambdaMax, read again after every call (the receiver may shorten it).
  template <typename Hit>
  void rayTest(const RayQuery& ray, Hit&& hit) const;
  /// Calls hit(id) for each box that overlaps `box` (boxesOverlap).
  template <typename Hit>
  void aabbTest(const Aabb& box, Hit&& hit) const;
  /// Whether rayTest walks the tree for this ray (else it tests every box).
  static bool walksTree(const RayQuery& ray);

 private:
  static constexpr std::uint32_t kEmpty = ~0u;
  struct Node {
    alignas(16) std::array<std::array<float, 4>, 3> lo;  // lo[axis][child]
    std::array<std::array<float, 4>, 3> hi;
    std::array<std::uint32_t, 4> child;  // a node, or on the first level a position in ids_
    unsigned used = 0;                   // bit l: lane l holds a child (an empty lane's box is inverted)
  };
  // A query's numbers in every lane.
  struct RaySplat {
    explicit RaySplat(const RayQuery& ray);
    __m128 from[3], inverse[3], growMin[3], growMax[3];
    bool negative[3];
  };
  struct BoxSplat {
    explicit BoxSplat(const Aabb& box);
    __m128 min[3], max[3];
  };
  // The four children's lanes the ray meets / the box overlaps, as bits.
  static unsigned rayLanes(const Node& node, const RaySplat& ray, float lambdaMax);
  static unsigned boxLanes(const Node& node, const BoxSplat& box);
  // Depth first from the root: lanesOf(node) picks the lanes to follow, leaf(position) gets each box's lane.
  template <typename Lanes, typename Leaf>
  void walk(Lanes&& lanesOf, Leaf&& leaf) const;
  void sortByMorton(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids);
  void buildLevels();

  std::vector<std::uint32_t> ids_;     // the boxes' ids in Morton order
  std::vector<Aabb> sorted_;           // their boxes, in the same order
  std::vector<Node> nodes_;            // the first level first; the root last
  std::size_t leafNodes_ = 0;          // nodes of the first level
  std::vector<std::uint64_t> keys_, scratch_;
};

// A walk keeps at most three siblings a level waiting: 3 * 16 levels hold 4^16 boxes and more.
inline constexpr std::size_t kWalkStack = 64;

// The node test: per child, btRayAabb2's slab times in its float operations
// (SSE computes each lane as the scalar code would). For a box the ray
// meets, every axis's entry time lies at or below every axis's exit time;
// taken together that is the latest entry at or below the earliest exit, and
// each time only moves outwards as the box grows.
inline unsigned BoxTree::rayLanes(const Node& node, const RaySplat& ray, float lambdaMax) {
  __m128 enter = _mm_set1_ps(-std::numeric_limits<float>::infinity()), leave = _mm_set1_ps(std::numeric_limits<float>::infinity());
  for (int a = 0; a < 3; ++a) {
    const __m128 t0 = _mm_mul_ps(_mm_sub_ps(_mm_sub_ps(_mm_load_ps(node.lo[a].data()), ray.growMax[a]), ray.from[a]),
                                 ray.inverse[a]);
    const __m128 t1 = _mm_mul_ps(_mm_sub_ps(_mm_sub_ps(_mm_load_ps(node.hi[a].data()), ray.growMin[a]), ray.from[a]),
                                 ray.inverse[a]);
    enter = _mm_max_ps(enter, ray.negative[a] ? t1 : t0);
    leave = _mm_min_ps(leave, ray.negative[a] ? t0 : t1);
  }
  const __m128 met = _mm_and_ps(_mm_cmple_ps(enter, leave),
                                _mm_and_ps(_mm_cmplt_ps(enter, _mm_set1_ps(lambdaMax)), _mm_cmpgt_ps(leave, _mm_setzero_ps())));
  return static_cast<unsigned>(_mm_movemask_ps(met));
}

inline BoxTree::RaySplat::RaySplat(const RayQuery& ray) {
  for (int a = 0; a < 3; ++a) {
    from[a] = _mm_set1_ps(ray.from[a]);
    inverse[a] = _mm_set1_ps(ray.inverseDirection[a]);
    growMin[a] = _mm_set1_ps(ray.grow.min[a]);
    growMax[a] = _mm_set1_ps(ray.grow.max[a]);
    negative[a] = ray.signs[a] != 0;
  }
}

// Apart where the node's min lies above the box's max or its max below the box's min (boxesOverlap).
inline unsigned BoxTree::boxLanes(const Node& node, const BoxSplat& box) {
  __m128 apart = _mm_setzero_ps();
  for (int a = 0; a < 3; ++a)
    apart = _mm_or_ps(apart, _mm_or_ps(_mm_cmpgt_ps(_mm_load_ps(node.lo[a].data()), box.max[a]),
                                       _mm_cmplt_ps(_mm_load_ps(node.hi[a].data()), box.min[a])));
  return static_cast<unsigned>(_mm_movemask_ps(apart)) ^ 0xFu;
}

inline BoxTree::BoxSplat::BoxSplat(const Aabb& box) {
  for (int a = 0; a < 3; ++a) {
    min[a] = _mm_set1_ps(box.min[a]);
    max[a] = _mm_set1_ps(box.max[a]);
  }
}

template <typename Lanes, typename Leaf>
void BoxTree::walk(Lanes&& lanesOf, Leaf&& leaf) const {
  if (nodes_.empty()) return;
  std::array<std::uint32_t, kWalkStack> stack;
  std::size_t depth = 0;
  stack[depth++] = static_cast<std::uint32_t>(nodes_.size() - 1);
  while (depth) {
    const std::uint32_t n = stack[--depth];
    const Node& node = nodes_[n];
    for (unsigned lanes = lanesOf(node) & node.used; lanes; lanes &= lanes - 1) {
      const std::uint32_t c = node.child[static_cast<unsigned>(__builtin_ctz(lanes))];
      if (n >= leafNodes_)
        stack[depth++] = c;
      else
        leaf(c);
    }
  }
}

template <typename Hit>
void BoxTree::rayTest(const RayQuery& ray, Hit&& hit) const {
  if (!walksTree(ray)) {
    for (std::size_t k = 0; k < ids_.size(); ++k)
      if (rayMeetsBox(ray, sorted_[k], ray.lambdaMax)) hit(ids_[k]);
    return;
  }
  const RaySplat splat(ray);
  walk([&](const Node& node) { return rayLanes(node, splat, ray.lambdaMax); },
       [&](std::uint32_t c) {
         if (rayMeetsBox(ray, sorted_[c], ray.lambdaMax)) hit(ids_[c]);  // the ray may be shorter than at the node
       });
}

template <typename Hit>
void BoxTree::aabbTest(const Aabb& box, Hit&& hit) const {
  const BoxSplat splat(box);
  walk([&](const Node& node) { return boxLanes(node, splat); }, [&](std::uint32_t c) { hit(ids_[c]); });
}

}  // namespace bpaccel
