#include "broad_phase.hpp"

#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "keys.hpp"

namespace bpaccel {
namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// Which pairs of a two-chunk run to keep (see BroadPhase::processCell).
enum Keep : int { kCross = 1, kFirstInside = 2, kSecondInside = 4 };

}  // namespace

BroadPhase::BroadPhase(Backend& backend, std::optional<std::size_t> cellSize)
    : backend_(backend), cellSize_(cellSize) {
  if (cellSize_ && *cellSize_ < 1) throw std::invalid_argument("cell size must be at least 1");
  if (backend_.capacity() < 2) throw std::invalid_argument("backend capacity must be at least 2");
}

void BroadPhase::findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  const auto t0 = Clock::now();
  toKeys(boxes, keys_);
  const double convert = seconds(t0, Clock::now());
  findPairs(std::span<const KeyBox>(keys_), out);
  times_.convertSeconds = convert;
  times_.totalSeconds += convert;
}

void BroadPhase::findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out) {
  checkObjectCount(keys.size());
  out.clear();
  stats_ = {};
  times_ = {};
  const auto t0 = Clock::now();
  if (cellSize_) {
    tree_.build(keys, *cellSize_);
    const auto t1 = Clock::now();
    times_.treeSeconds = seconds(t0, t1);
    for (const KdTree::Leaf& leaf : tree_.leaves()) processCell(keys, tree_.items(leaf), &leaf, out);
    times_.cellsSeconds = seconds(t1, Clock::now());
  } else {
    identity_.resize(keys.size());
    std::iota(identity_.begin(), identity_.end(), 0u);
    processCell(keys, identity_, nullptr, out);
    times_.cellsSeconds = seconds(t0, Clock::now());
  }
  times_.totalSeconds = times_.treeSeconds + times_.cellsSeconds;
}

// A cell within capacity is one run. A larger one is cut into k chunks of at
// most capacity/2 boxes; chunks p < q run together and keep their cross
// pairs, and each chunk's inside pairs are kept from exactly one run: chunk
// p from run (p, p+1), the last chunk from run (k-2, k-1).
void BroadPhase::processCell(std::span<const KeyBox> keys, std::span<const std::uint32_t> items,
                             const KdTree::Leaf* region, std::vector<Pair>& out) {
  const std::size_t cap = backend_.capacity();
  if (items.size() < 2) return;
  if (items.size() <= cap) {
    runBatch(keys, items, region, out, items.size(), kFirstInside);
    return;
  }
  const std::size_t chunk = cap / 2;
  const std::size_t k = (items.size() + chunk - 1) / chunk;
  std::vector<std::uint32_t> pairItems;  // rare path (cell beyond capacity): allocation is fine here
  for (std::size_t p = 0; p < k; ++p) {
    for (std::size_t q = p + 1; q < k; ++q) {
      const auto first = items.subspan(p * chunk, std::min(chunk, items.size() - p * chunk));
      const auto second = items.subspan(q * chunk, std::min(chunk, items.size() - q * chunk));
      pairItems.assign(first.begin(), first.end());
      pairItems.insert(pairItems.end(), second.begin(), second.end());
      int keep = kCross;
      if (q == p + 1) keep |= kFirstInside;
      if (p == k - 2 && q == k - 1) keep |= kSecondInside;
      runBatch(keys, pairItems, region, out, first.size(), keep);
    }
  }
}

void BroadPhase::runBatch(std::span<const KeyBox> keys, std::span<const std::uint32_t> items,
                          const KdTree::Leaf* region, std::vector<Pair>& out, std::size_t splitAt, int keep) {
  batch_.resize(items.size());
  for (std::size_t t = 0; t < items.size(); ++t) batch_[t] = keys[items[t]];
  local_.clear();
  const auto t0 = Clock::now();
  backend_.run(batch_, local_, stats_);
  times_.backendSeconds += seconds(t0, Clock::now());
  for (const auto& [a, b] : local_) {
    const bool firstA = a < splitAt, firstB = b < splitAt;
    const int kind = firstA != firstB ? kCross : (firstA ? kFirstInside : kSecondInside);
    if (!(keep & kind)) continue;
    if (region && !region->contains(referencePoint(batch_[a], batch_[b]))) continue;
    const std::uint32_t i = items[a], j = items[b];
    out.emplace_back(std::min(i, j), std::max(i, j));
  }
}

}  // namespace bpaccel
