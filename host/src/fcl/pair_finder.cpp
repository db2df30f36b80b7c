#include "pair_finder.hpp"

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

}  // namespace bpaccel
