#include "broad_phase.hpp"

#include <numeric>
#include <stdexcept>
#include <utility>

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "../core/keys.hpp"
#include "binning_frame.hpp"
#include "hand_over.hpp"
#include "host_frame.hpp"
#include "timing.hpp"
#include "worker.hpp"

namespace bpaccel {

/// The threads of a multi-threaded BroadPhase: an arena of its own, so the
/// thread count is this object's and nothing is shared with other users of TBB.
class BroadPhase::Pool {
 public:
  explicit Pool(std::size_t threads) : arena_(static_cast<int>(threads)) {}
  template <typename F>
  void run(F&& f) {
    arena_.execute(std::forward<F>(f));
  }

 private:
  tbb::task_arena arena_;
};

BroadPhase::BroadPhase(Backend& backend, const BroadPhaseConfig& config) : config_(config) {
  config_.check();
  if (config_.threads != 1 || config_.handOvers != HandOvers::Synchronous)
    throw std::invalid_argument("broad phase: several threads or asynchronous hand-overs need a backend factory");
  if (const AllPairsKernel* kernel = backend.hostKernel()) {
    host_ = std::make_unique<HostFrame>(*kernel, config_);
    return;
  }
  startWorkers([&] {
    return std::make_unique<Worker>(
        [&](AnswerDecoder& decoder, HandOverTimer& timer) {
          return std::make_unique<SynchronousHandOver>(backend, decoder, timer);
        },
        config_.cellsPerBatch, config_.firstBatch(), config_.observer != nullptr);
  });
}

BroadPhase::BroadPhase(const BackendFactory& makeBackend, const BroadPhaseConfig& config) : config_(config) {
  config_.check();
  if (config_.handOvers == HandOvers::Synchronous) {
    const std::unique_ptr<Backend> probe = makeBackend();
    if (probe && probe->hostKernel()) {
      host_ = std::make_unique<HostFrame>(*probe->hostKernel(), config_);
      return;
    }
  }
  startWorkers([&] {
    return std::make_unique<Worker>(
        [&](AnswerDecoder& decoder, HandOverTimer& timer) {
          return HandOver::make(config_.handOvers, makeBackend, decoder, timer);
        },
        config_.cellsPerBatch, config_.firstBatch(), config_.observer != nullptr);
  });
}

void BroadPhase::startWorkers(const std::function<std::unique_ptr<Worker>()>& makeWorker) {
  for (std::size_t t = 0; t < config_.threads; ++t) workers_.push_back(makeWorker());
  capacity_ = workers_.front()->backend().capacity;
  if (capacity_ < 2) throw std::invalid_argument("broad phase: backend capacity must be at least 2");
  tree_ = makePartition(PartitionKind::KdTree);
  grid_ = makePartition(PartitionKind::UniformGrid);
  partition_ = config_.partition == PartitionKind::UniformGrid ? grid_.get() : tree_.get();
  if (config_.threads > 1) pool_ = std::make_unique<Pool>(config_.threads);
}

BroadPhase::BroadPhase(FrameDevice& device, const BroadPhaseConfig& config) : config_(config) {
  config_.check();
  if (config_.threads != 1 || config_.handOvers != HandOvers::Synchronous)
    throw std::invalid_argument("broad phase: a binning device runs one thread with synchronous hand-overs");
  binning_ = std::make_unique<BinningFrame>(device);
}

BroadPhase::~BroadPhase() = default;

void BroadPhase::awakenDevices() {
  if (config_.handOvers != HandOvers::Polled) return;
  for (auto& w : workers_) w->awaken();
}

const RunStats& BroadPhase::stats() const { return host_ ? host_->stats() : stats_; }
const Partition& BroadPhase::partition() const {
  if (binning_) throw std::logic_error("broad phase: a binning device partitions the scene itself");
  return host_ ? host_->partition() : *partition_;
}
const CellChoice& BroadPhase::choice() const { return host_ ? host_->choice() : choice_; }
std::size_t BroadPhase::threads() const { return host_ ? host_->threads() : binning_ ? 1 : workers_.size(); }

void BroadPhase::chooseCells(std::size_t objects, const KeyBounds* bounds) {
  if (config_.cellSize.isAutomatic()) {
    choice_ = chooser_.choose(objects, bounds ? *bounds : KeyBounds{}, config_.partition);
  } else {
    const PartitionKind kind =
        config_.partition == PartitionKind::UniformGrid ? PartitionKind::UniformGrid : PartitionKind::KdTree;
    choice_ = {kind, config_.cellSize.fixed()};
  }
  partition_ = choice_.kind == PartitionKind::UniformGrid ? grid_.get() : tree_.get();
}

BroadPhase::Clock::time_point BroadPhase::now() const {
  return config_.observer ? Clock::now() : Clock::time_point{};
}

void BroadPhase::findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  if (binning_) {
    binning_->findPairs(boxes, out);
    const BinningFrameStats& b = binning_->stats();
    stats_ = {};
    stats_.runs = stats_.batches = b.frames + b.retries;
    stats_.cycles = b.deviceCycles;
    stats_.issueCycles = b.issueCycles;
    stats_.hits = b.devicePairs;
    stats_.boxesSent = b.boxesSent;
    return;
  }
  if (host_) {
    host_->findPairs(boxes, out);
    if (config_.observer) config_.observer->frameFinished(host_->timing());
    return;
  }
  const auto t0 = now();
  // The bounds in the same pass when the partition will use them (timed as
  // conversion): the grid's, and the automatic choice's.
  const bool withBounds = config_.cellSize.isAutomatic() ||
                          (config_.cellSize.fixed() && config_.partition == PartitionKind::UniformGrid);
  KeyBounds bounds;
  if (withBounds)
    toKeys(boxes, keys_, bounds);
  else
    toKeys(boxes, keys_);
  const double convert = FrameClock::seconds(t0, now());
  findKeyPairs(std::span<const KeyBox>(keys_), out, withBounds ? &bounds : nullptr);
  if (!config_.observer) return;
  timing_.times.convertSeconds = convert;
  timing_.times.totalSeconds += convert;
  for (HandOverRecord& r : timing_.handOvers) r.readySeconds += convert;  // the conversion came first
  config_.observer->frameFinished(timing_);
}

void BroadPhase::findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out) {
  if (binning_) throw std::logic_error("broad phase: a binning device takes float boxes, not keys");
  if (host_) {
    host_->findPairs(keys, out);
    if (config_.observer) config_.observer->frameFinished(host_->timing());
    return;
  }
  findKeyPairs(keys, out, nullptr);
  if (config_.observer) config_.observer->frameFinished(timing_);
}

void BroadPhase::findKeyPairs(std::span<const KeyBox> keys, std::vector<Pair>& out, const KeyBounds* bounds) {
  checkObjectCount(keys.size());
  out.clear();
  stats_ = {};
  timing_.times = {};
  const auto t0 = now();
  KeyBounds found;
  if (!bounds && config_.cellSize.isAutomatic()) {
    found = boundsOf(keys);
    bounds = &found;
  }
  chooseCells(keys.size(), bounds);
  for (auto& w : workers_) w->startFrame(t0);
  if (!choice_.cellSize) {
    identity_.resize(keys.size());
    std::iota(identity_.begin(), identity_.end(), 0u);
    workers_.front()->processCell(keys, DeviceCell::whole(identity_, keys, {}, nullptr, true));
    workers_.front()->finish();
    timing_.times.cellsSeconds = FrameClock::seconds(t0, now());
  } else if (!pool_) {
    streamCells(keys, bounds);
  } else {
    streamCellsToThreads(keys, bounds);
  }
  finishCells(out);
  if (config_.cellSize.isAutomatic() && choice_.cellSize) chooser_.observe(choice_, occupancyOf(*partition_, keys.size()));
  timing_.times.totalSeconds = timing_.times.partitionSeconds + timing_.times.cellsSeconds;
}

// Each cell goes to the device as soon as the partition has made it: the tree
// hands each leaf to a sink while it goes on (the first run is ready long
// before the tree is finished); other partitions tell when a prefix of their
// cells is final (the grid: slab by slab), and those cells are gone through
// here, with no call through a sink and no clock read per cell.
void BroadPhase::streamCells(std::span<const KeyBox> keys, const KeyBounds* bounds) {
  const auto t0 = now();
  Worker& w = *workers_.front();
  double inCells = 0;
  const bool lasting = partition_->cellsOutliveBuild();
  if (partition_->streamsCells()) {
    partition_->build(keys, *choice_.cellSize, [&](const Cell& leaf, std::span<const std::uint32_t> items,
                                                   std::span<const KeyBox> packed) {
      const auto c0 = now();
      w.processCell(keys, DeviceCell::whole(items, packed, {}, &leaf, lasting));
      inCells += FrameClock::seconds(c0, now());
    }, bounds);
  } else {
    std::size_t done = 0;
    const auto processUpTo = [&](std::size_t finalCells) {
      const auto c0 = now();
      const auto& cells = partition_->cells();
      for (; done < finalCells; ++done) {
        const Cell& cell = cells[done];
        w.processCell(keys, DeviceCell::whole(partition_->items(cell), partition_->packed(cell),
                                              partition_->below(cell), &cell, lasting));
      }
      inCells += FrameClock::seconds(c0, now());
    };
    // One reference captured: the sink fits std::function's own storage (no allocation a frame).
    partition_->buildInSteps(keys, *choice_.cellSize, [&processUpTo](std::size_t k) { processUpTo(k); }, bounds);
  }
  const auto f0 = now();
  w.finish();  // the last, partly filled batch
  inCells += FrameClock::seconds(f0, now());
  timing_.times.cellsSeconds = inCells;
  timing_.times.partitionSeconds = FrameClock::seconds(t0, now()) - inCells;
}

// The calling thread builds the partition and hands each cell to the pool as
// a task while it goes on; the other threads process cells meanwhile, and the
// builder joins them when the partition is done. A task gets its own copy of
// the cell's items and boxes: the tree's storage changes as the build goes on.
void BroadPhase::streamCellsToThreads(std::span<const KeyBox> keys, const KeyBounds* bounds) {
  const auto t0 = now();
  Clock::time_point built;
  pool_->run([&] {
    tbb::task_group tasks;
    std::size_t used = 0;
    partition_->build(keys, *choice_.cellSize, [&](const Cell& leaf, std::span<const std::uint32_t> items,
                                                   std::span<const KeyBox> packed) {
      if (items.size() < 2) return;  // no pair
      if (used == cellCopies_.size()) cellCopies_.emplace_back();  // a deque: earlier copies stay put
      CellCopy& copy = cellCopies_[used++];
      copy.items.assign(items.begin(), items.end());
      copy.packed.assign(packed.begin(), packed.end());
      tasks.run([this, keys, leaf, &copy] {
        // Inside this arena, thread indices are 0 .. threads-1: one worker each.
        Worker& w = *workers_.at(static_cast<std::size_t>(tbb::this_task_arena::current_thread_index()));
        w.processCell(keys, DeviceCell::whole(copy.items, copy.packed, {}, &leaf, false));
      });
    }, bounds);
    built = now();
    tasks.wait();
    // Each worker's last, partly filled batch; no task runs any more, so
    // this thread may use every worker's device.
    for (auto& w : workers_) w->finish();
  });
  timing_.times.partitionSeconds = FrameClock::seconds(t0, built);
  timing_.times.cellsSeconds = FrameClock::seconds(built, now());
}

void BroadPhase::finishCells(std::vector<Pair>& out) {
  timing_.handOvers.clear();
  // One worker hands its pairs over without a copy (and takes the caller's empty buffer for the next frame).
  if (workers_.size() == 1) out.swap(workers_.front()->pairs());
  for (auto& w : workers_) {
    if (workers_.size() > 1) out.insert(out.end(), w->pairs().begin(), w->pairs().end());
    stats_ += w->stats();
    timing_.times.backendSeconds += w->timer().backendSeconds();
    const auto& records = w->timer().records();
    timing_.handOvers.insert(timing_.handOvers.end(), records.begin(), records.end());
  }
}

}  // namespace bpaccel
