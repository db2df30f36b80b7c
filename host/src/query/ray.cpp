#include "ray.hpp"

#include <cmath>

namespace bpaccel {

RayQuery RayQuery::segment(const std::array<float, 3>& from, const std::array<float, 3>& to) {
  RayQuery ray;
  ray.from = from;
  const std::array<float, 3> v = {to[0] - from[0], to[1] - from[1], to[2] - from[2]};
  const float length2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  std::array<float, 3> direction = {1, 0, 0};
  if (length2 > 0) {
    const float inverseLength = 1.0f / std::sqrt(length2);
    direction = {v[0] * inverseLength, v[1] * inverseLength, v[2] * inverseLength};
  }
  for (int a = 0; a < 3; ++a) {
    ray.inverseDirection[a] = direction[a] == 0.0f ? kLargeInverse : 1.0f / direction[a];
    ray.signs[a] = ray.inverseDirection[a] < 0.0f ? 1u : 0u;
  }
  ray.lambdaMax = direction[0] * v[0] + direction[1] * v[1] + direction[2] * v[2];
  return ray;
}

// Bullet's btRayAabb2 (LinearMath/btAabbUtil2.h), its comparisons kept in
// order so that NaN goes the same way.
bool rayMeetsBox(const RayQuery& ray, const Aabb& box, float lambdaMax) {
  float bounds[2][3];
  for (int a = 0; a < 3; ++a) {
    bounds[0][a] = box.min[a] - ray.grow.max[a];
    bounds[1][a] = box.max[a] - ray.grow.min[a];
  }
  // A sign other than 0 or 1 (Bullet sets none) counts as 1 rather than index out of bounds.
  const std::array<unsigned, 3> s = {ray.signs[0] != 0, ray.signs[1] != 0, ray.signs[2] != 0};
  const auto& inv = ray.inverseDirection;
  const auto& f = ray.from;
  float tmin = (bounds[s[0]][0] - f[0]) * inv[0];
  float tmax = (bounds[1 - s[0]][0] - f[0]) * inv[0];
  const float tymin = (bounds[s[1]][1] - f[1]) * inv[1];
  const float tymax = (bounds[1 - s[1]][1] - f[1]) * inv[1];
  if ((tmin > tymax) || (tymin > tmax)) return false;
  if (tymin > tmin) tmin = tymin;
  if (tymax < tmax) tmax = tymax;
  const float tzmin = (bounds[s[2]][2] - f[2]) * inv[2];
  const float tzmax = (bounds[1 - s[2]][2] - f[2]) * inv[2];
  if ((tmin > tzmax) || (tzmin > tmax)) return false;
  if (tzmin > tmin) tmin = tzmin;
  if (tzmax < tmax) tmax = tzmax;
  return (tmin < lambdaMax) && (tmax > 0.0f);
}

}  // namespace bpaccel
