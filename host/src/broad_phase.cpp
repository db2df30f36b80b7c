#include "broad_phase.hpp"

#include <numeric>
#include <stdexcept>

#include <fmt/format.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "keys.hpp"

namespace bpaccel {
namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// Which pairs of a two-chunk run to keep (see processCell).
enum Keep : int { kCross = 1, kFirstInside = 2, kSecondInside = 4 };

}  // namespace

/// What one thread needs to process cells: its backend and its buffers.
struct BroadPhase::Worker {
  std::unique_ptr<Backend> owned;
  Backend* backend = nullptr;
  std::vector<KeyBox> gathered;         // a chunk pair's boxes, packed for the backend
  std::vector<Pair> local;              // pairs of one run, batch indices
  std::vector<Pair> out;                // this worker's share of the frame's pairs
  RunStats stats;
  double backendSeconds = 0;
  Clock::time_point frameStart;
  std::vector<RunRecord> runs;

  // `packed`: the cell's boxes in item order when the caller has them (the
  // tree's leaves, the whole scene), else empty: they are gathered from `keys`.
  void runBatch(std::span<const KeyBox> keys, std::span<const std::uint32_t> items, std::span<const KeyBox> packed,
                const KdTree::Leaf* region, std::size_t splitAt, int keep);
  void processCell(std::span<const KeyBox> keys, std::span<const std::uint32_t> items, std::span<const KeyBox> packed,
                   const KdTree::Leaf* region, std::size_t capacity);
};

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

BroadPhase::BroadPhase(Backend& backend, std::optional<std::size_t> cellSize)
    : cellSize_(cellSize), capacity_(backend.capacity()) {
  auto w = std::make_unique<Worker>();
  w->backend = &backend;
  workers_.push_back(std::move(w));
  check();
}

BroadPhase::BroadPhase(const BackendFactory& makeBackend, std::optional<std::size_t> cellSize, std::size_t threads)
    : cellSize_(cellSize) {
  if (threads < 1) throw std::invalid_argument("broad phase: at least one thread");
  for (std::size_t t = 0; t < threads; ++t) {
    auto w = std::make_unique<Worker>();
    w->owned = makeBackend();
    if (!w->owned) throw std::invalid_argument("broad phase: the backend factory gave no backend");
    w->backend = w->owned.get();
    workers_.push_back(std::move(w));
  }
  capacity_ = workers_.front()->backend->capacity();
  if (threads > 1) pool_ = std::make_unique<Pool>(threads);
  check();
}

BroadPhase::~BroadPhase() = default;

void BroadPhase::check() const {
  if (cellSize_ && *cellSize_ < 1) throw std::invalid_argument("cell size must be at least 1");
  if (capacity_ < 2) throw std::invalid_argument("backend capacity must be at least 2");
}

void BroadPhase::findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  const auto t0 = Clock::now();
  toKeys(boxes, keys_);
  const double convert = seconds(t0, Clock::now());
  findPairs(std::span<const KeyBox>(keys_), out);
  times_.convertSeconds = convert;
  times_.totalSeconds += convert;
  for (RunRecord& r : runs_) r.readySeconds += convert;  // the conversion came first
}

void BroadPhase::findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out) {
  checkObjectCount(keys.size());
  out.clear();
  stats_ = {};
  times_ = {};
  const auto t0 = Clock::now();
  startCells(t0);
  if (!cellSize_) {
    identity_.resize(keys.size());
    std::iota(identity_.begin(), identity_.end(), 0u);
    workers_.front()->processCell(keys, identity_, keys, nullptr, capacity_);
    times_.cellsSeconds = seconds(t0, Clock::now());
  } else if (!pool_) {
    streamCells(keys);
  } else {
    streamCellsToThreads(keys);
  }
  finishCells(out);
  times_.totalSeconds = times_.treeSeconds + times_.cellsSeconds;
}

// Each cell goes to the backend as soon as the tree has made it, so the
// first run is ready long before the tree is finished.
void BroadPhase::streamCells(std::span<const KeyBox> keys) {
  const auto t0 = Clock::now();
  Worker& w = *workers_.front();
  double inCells = 0;
  tree_.build(keys, *cellSize_, [&](const KdTree::Leaf& leaf, std::span<const std::uint32_t> items,
                                    std::span<const KeyBox> packed) {
    const auto c0 = Clock::now();
    w.processCell(keys, items, packed, &leaf, capacity_);
    inCells += seconds(c0, Clock::now());
  });
  times_.cellsSeconds = inCells;
  times_.treeSeconds = seconds(t0, Clock::now()) - inCells;
}

// The calling thread builds the tree and hands each cell to the pool as a
// task while it goes on; the other threads process cells meanwhile, and the
// builder joins them when the tree is done. A task gets its own copy of the
// cell's items and boxes: the tree's storage changes as the build goes on.
void BroadPhase::streamCellsToThreads(std::span<const KeyBox> keys) {
  const auto t0 = Clock::now();
  Clock::time_point built;
  pool_->run([&] {
    tbb::task_group tasks;
    std::size_t used = 0;
    tree_.build(keys, *cellSize_, [&](const KdTree::Leaf& leaf, std::span<const std::uint32_t> items,
                                      std::span<const KeyBox> packed) {
      if (items.size() < 2) return;  // no pair
      if (used == cellCopies_.size()) cellCopies_.emplace_back();  // a deque: earlier copies stay put
      CellCopy& copy = cellCopies_[used++];
      copy.items.assign(items.begin(), items.end());
      copy.packed.assign(packed.begin(), packed.end());
      tasks.run([this, keys, leaf, &copy] {
        // Inside this arena, thread indices are 0 .. threads-1: one worker each.
        Worker& w = *workers_.at(static_cast<std::size_t>(tbb::this_task_arena::current_thread_index()));
        w.processCell(keys, copy.items, copy.packed, &leaf, capacity_);
      });
    });
    built = Clock::now();
    tasks.wait();
  });
  times_.treeSeconds = seconds(t0, built);
  times_.cellsSeconds = seconds(built, Clock::now());
}

void BroadPhase::startCells(Clock::time_point frameStart) {
  for (auto& w : workers_) {
    w->out.clear();
    w->stats = {};
    w->backendSeconds = 0;
    w->frameStart = frameStart;
    w->runs.clear();
  }
}

void BroadPhase::finishCells(std::vector<Pair>& out) {
  runs_.clear();
  for (auto& w : workers_) {
    out.insert(out.end(), w->out.begin(), w->out.end());
    stats_ += w->stats;
    times_.backendSeconds += w->backendSeconds;
    runs_.insert(runs_.end(), w->runs.begin(), w->runs.end());
  }
}

// A cell within capacity is one run. A larger one is cut into k chunks of at
// most capacity/2 boxes; chunks p < q run together and keep their cross
// pairs, and each chunk's inside pairs are kept from exactly one run: chunk
// p from run (p, p+1), the last chunk from run (k-2, k-1).
void BroadPhase::Worker::processCell(std::span<const KeyBox> keys, std::span<const std::uint32_t> items,
                                     std::span<const KeyBox> packed, const KdTree::Leaf* region,
                                     std::size_t capacity) {
  if (items.size() < 2) return;
  if (items.size() <= capacity) {
    runBatch(keys, items, packed, region, items.size(), kFirstInside);
    return;
  }
  const std::size_t chunk = capacity / 2;
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
      runBatch(keys, pairItems, {}, region, first.size(), keep);
    }
  }
}

void BroadPhase::Worker::runBatch(std::span<const KeyBox> keys, std::span<const std::uint32_t> items,
                                  std::span<const KeyBox> packed, const KdTree::Leaf* region, std::size_t splitAt,
                                  int keep) {
  if (packed.empty()) {
    gathered.resize(items.size());
    for (std::size_t t = 0; t < items.size(); ++t) gathered[t] = keys[items[t]];
    packed = gathered;
  }
  local.clear();
  RunRecord record;
  const auto ready = Clock::now();
  record.readySeconds = seconds(frameStart, ready) - backendSeconds;
  backend->run(packed, local, record.stats);
  const auto ran = Clock::now();
  backendSeconds += seconds(ready, ran);
  stats += record.stats;
  for (const auto& [a, b] : local) {
    const bool firstA = a < splitAt, firstB = b < splitAt;
    const int kind = firstA != firstB ? kCross : (firstA ? kFirstInside : kSecondInside);
    if (!(keep & kind)) continue;
    if (region && !region->contains(referencePoint(packed[a], packed[b]))) continue;
    const std::uint32_t i = items[a], j = items[b];
    out.emplace_back(std::min(i, j), std::max(i, j));
  }
  record.decodeSeconds = seconds(ran, Clock::now());
  runs.push_back(record);
}

}  // namespace bpaccel
