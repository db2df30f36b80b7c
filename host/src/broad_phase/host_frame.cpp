#include "host_frame.hpp"

#include <chrono>

#include "../core/keys.hpp"
#include "../partition/kd_tree.hpp"
#include "../partition/uniform_grid.hpp"

namespace bpaccel {
namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point from, Clock::time_point to) { return std::chrono::duration<double>(to - from).count(); }

}  // namespace

/// One thread's share of a frame.
struct HostFrame::Local {
  AllPairsKernel::Scratch scratch;
  std::vector<Pair> pairs;
  std::vector<std::uint8_t> below;  // a tree cell's below() bits, from its region
  RunStats stats;
};

HostFrame::HostFrame(const AllPairsKernel& kernel, const BroadPhaseConfig& config)
    : kernel_(kernel),
      config_(config),
      pool_(config.threads),
      tree_(std::make_unique<KdTree>()),
      grid_(std::make_unique<UniformGrid>()),
      used_(grid_.get()),
      locals_(config.threads) {
  config_.check();
}

HostFrame::~HostFrame() = default;

void HostFrame::findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  const bool timed = config_.observer != nullptr;
  const auto t0 = timed ? Clock::now() : Clock::time_point{};
  KeyBounds bounds;
  toKeys(boxes, keys_, bounds, pool_);
  const double convert = timed ? seconds(t0, Clock::now()) : 0;
  findKeyPairs(keys_, &bounds, out);
  timing_.times.convertSeconds = convert;
  timing_.times.totalSeconds += convert;
}

void HostFrame::findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out) {
  checkObjectCount(keys.size());
  findKeyPairs(keys, nullptr, out);
}

CellChoice HostFrame::choose(std::span<const KeyBox> keys, const KeyBounds& bounds) {
  if (!config_.cellSize.isAutomatic()) {
    const PartitionKind kind =
        config_.partition == PartitionKind::UniformGrid ? PartitionKind::UniformGrid : PartitionKind::KdTree;
    return {kind, config_.cellSize.fixed()};
  }
  return chooser_.choose(keys.size(), bounds, config_.partition);
}

void HostFrame::findKeyPairs(std::span<const KeyBox> keys, const KeyBounds* given, std::vector<Pair>& out) {
  const bool timed = config_.observer != nullptr;
  const auto t0 = timed ? Clock::now() : Clock::time_point{};
  const KeyBounds bounds = given ? *given : boundsOf(keys);
  choice_ = choose(keys, bounds);
  for (Local& l : locals_) {
    l.pairs.clear();
    l.stats = {};
  }
  if (choice_.cellSize) {
    used_ = choice_.kind == PartitionKind::UniformGrid ? grid_.get() : tree_.get();
    used_->buildIndex(keys, *choice_.cellSize, &bounds, &pool_);
    if (config_.cellSize.isAutomatic()) chooser_.observe(choice_, occupancyOf(*used_, keys.size()));
  }
  const auto t1 = timed ? Clock::now() : Clock::time_point{};
  if (choice_.cellSize) {
    runCells(keys);
  } else {
    if (config_.cellSize.isAutomatic()) chooser_.observe(choice_, {keys.size(), keys.size(), 0, 1});
    Local& l = locals_.front();
    kernel_.ownedPairs({keys, {}, {}}, l.pairs, l.scratch);
    l.stats.runs = l.stats.batches = keys.size() >= 2;
  }
  join(out);
  if (!timed) return;
  const auto t2 = Clock::now();
  timing_ = {};
  timing_.times.partitionSeconds = seconds(t0, t1);
  timing_.times.cellsSeconds = seconds(t1, t2);
  timing_.times.totalSeconds = seconds(t0, t2);
}

void HostFrame::runCells(std::span<const KeyBox> keys) {
  const std::vector<Cell>& cells = used_->cells();
  pool_.forEach(cells.size(), [&](std::size_t k) { runCell(keys, cells[k], locals_[pool_.thisThread()]); });
}

void HostFrame::runCell(std::span<const KeyBox> keys, const Cell& cell, Local& local) const {
  const std::span<const std::uint32_t> items = used_->items(cell);
  if (items.size() < 2) return;
  std::span<const std::uint8_t> below = used_->below(cell);
  if (below.empty()) {  // the tree's cells: the bits from the region
    local.below.resize(items.size());
    for (std::size_t k = 0; k < items.size(); ++k) local.below[k] = belowBits(keys[items[k]].min, cell.lo);
    below = local.below;
  }
  kernel_.ownedPairs({keys, items, below, true}, local.pairs, local.scratch);
  ++local.stats.runs;
  ++local.stats.batches;
}

// The threads' pairs into `out`: the first thread's by a swap (its buffer
// then serves the caller's next frame), the others' appended.
void HostFrame::join(std::vector<Pair>& out) {
  out.clear();
  stats_ = {};
  out.swap(locals_.front().pairs);
  for (std::size_t t = 1; t < locals_.size(); ++t) out.insert(out.end(), locals_[t].pairs.begin(), locals_[t].pairs.end());
  for (const Local& l : locals_) stats_ += l.stats;
  stats_.hits = out.size();
}

}  // namespace bpaccel
