#include "pair_finder.hpp"

#include <cmath>
#include <limits>

namespace bpaccel {

PairFinder::PairFinder(std::unique_ptr<Backend> backend, const BroadPhaseConfig& config)
    : backend_(std::move(backend)), phase_(std::make_unique<BroadPhase>(*backend_, config)) {}

PairFinder::PairFinder(const BackendFactory& makeBackend, const BroadPhaseConfig& config)
    : phase_(std::make_unique<BroadPhase>(makeBackend, config)) {}

const std::vector<Pair>& PairFinder::find(std::span<const Aabb> boxes, std::size_t split) {
  phase_->findPairs(boxes, pairs_);
  if (split > 0)
    std::erase_if(pairs_, [split](const Pair& p) { return !(p.first < split && p.second >= split); });
  return pairs_;
}

float floatAtOrBelow(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::max();
  if (v < -kMax) return -std::numeric_limits<float>::infinity();
  const float f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}

float floatAtOrAbove(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v < -kMax) return -std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::infinity();
  const float f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

}  // namespace bpaccel
