#pragma once
// The overlapping pairs of a set of float boxes through BroadPhase: all of
// them, or only those across two groups.

#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "../broad_phase/broad_phase.hpp"
#include "../core/types.hpp"
#include "../device/backend.hpp"

namespace bpaccel {

class PairFinder {
 public:
  PairFinder(std::unique_ptr<Backend> backend, const BroadPhaseConfig& config);
  PairFinder(const BackendFactory& makeBackend, const BroadPhaseConfig& config);
  /// The pairs (i < j) of boxes that overlap inclusively; with `split` > 0
  /// only those with i < split <= j. Valid until the next call.
  const std::vector<Pair>& find(std::span<const Aabb> boxes, std::size_t split = 0);

 private:
  std::unique_ptr<Backend> backend_;  // the one backend, unless a factory makes them
  std::unique_ptr<BroadPhase> phase_;
  std::vector<Pair> pairs_;
};

/// The largest float at or below `v`, and the smallest at or above it (±infinity beyond float's range; NaN stays NaN).
/// Inline: every object's six bounds go through them at each update.
inline float floatAtOrBelow(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::max();
  if (v < -kMax) return -std::numeric_limits<float>::infinity();
  const float f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}

inline float floatAtOrAbove(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v < -kMax) return -std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::infinity();
  const float f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

}  // namespace bpaccel
