#pragma once
// Ray and box queries as Bullet's broad phases answer them: the ray, its
// test against one box, and the box test.

#include <array>
#include <cstdint>
#include <functional>

#include "../core/types.hpp"

namespace bpaccel {

/// A ray as btBroadphaseRayCallback carries it: the points from + t / inverseDirection
/// (per axis) for t in [0, lambdaMax]. `grow` is the query's box (Bullet's
/// aabbMin, aabbMax of a box cast): each box is tested grown by it, as
/// [box.min - grow.max, box.max - grow.min].
struct RayQuery {
  std::array<float, 3> from{};
  std::array<float, 3> inverseDirection{};
  /// 1 where inverseDirection is negative (Bullet's m_signs); segment() sets them.
  std::array<std::uint32_t, 3> signs{};
  float lambdaMax = 0;
  Aabb grow{{0, 0, 0}, {0, 0, 0}};

  /// The ray from `from` to `to` as btCollisionWorld::rayTest builds it: the
  /// direction normalised, 1e18 (Bullet's BT_LARGE_FLOAT) as the inverse of a
  /// zero component, lambdaMax the segment's length. A zero-length segment
  /// gets the direction +x and lambdaMax 0: it finds the boxes (grown by
  /// `grow`) that hold `from` strictly inside.
  static RayQuery segment(const std::array<float, 3>& from, const std::array<float, 3>& to);
};

/// Bullet's BT_LARGE_FLOAT in single precision: the inverse of a zero direction component.
inline constexpr float kLargeInverse = 1e18f;

/// btRayAabb2 on `box` grown by ray.grow, with lambda_min 0 and lambda_max
/// `lambdaMax`, operation for operation in float: the same answer as Bullet's
/// for every input, NaN and infinities included.
bool rayMeetsBox(const RayQuery& ray, const Aabb& box, float lambdaMax);

/// Inclusive overlap as Bullet decides it (TestAabbAgainstAabb2, and
/// btDbvt's Intersect in its SSE form): boxes are apart only where one's min
/// lies above the other's max, so touching boxes overlap and a box with NaN
/// overlaps every box.
inline bool boxesOverlap(const Aabb& a, const Aabb& b) {
  return !(a.min[0] > b.max[0] || a.max[0] < b.min[0] || a.min[1] > b.max[1] || a.max[1] < b.min[1] ||
           a.min[2] > b.max[2] || a.max[2] < b.min[2]);
}

/// Told each box a query finds, by id. A ray query reads RayQuery::lambdaMax
/// again after each call, so the receiver may shorten the ray as it goes.
using QueryHit = std::function<void(std::uint32_t id)>;

}  // namespace bpaccel
