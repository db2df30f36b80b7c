#include "broad_phase.hpp"

#include <algorithm>
#include <array>
#include <future>
#include <numeric>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "../device/async_backend.hpp"
#include "../core/keys.hpp"
#include "../device/serial_stage.hpp"

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
  std::unique_ptr<AsyncBackend> async;  // with asynchronous hand-overs: the backend on a thread of its own
  std::size_t cellsPerBatch = 1;
  std::size_t firstBatchCells = 1;  // the frame's first hand-over (see BroadPhase::setFirstBatchCells)
  std::size_t batchLimit = 1;       // cells that make the batch being filled full: doubles per hand-over
  // The device's key width (Backend::keyWidth). Below 32 each device cell
  // gets narrowed keys (narrowKeys) and its pairs are checked with the full ones.
  unsigned keyWidth = 32;
  bool narrows() const { return keyWidth < 32; }
  std::vector<KeyBox> narrowedRun;  // runNow's narrowed cell
  // The decoder's and the device's threads are stopped (after their last
  // batch) before the buffers they use go.
  ~Worker() {
    decoder.reset();
    async.reset();
  }
  std::vector<KeyBox> gathered;         // a chunk pair's boxes, packed for the backend
  std::vector<Pair> local;              // pairs of one hand-over, indices local to each cell
  std::vector<Pair> out;                // this worker's share of the frame's pairs
  RunStats stats;
  double backendSeconds = 0;
  Clock::time_point frameStart;
  std::vector<RunRecord> runs;

  // A batch: its cells' items and boxes (referred to where they outlive the
  // batch, else copied back to back), and how to filter each cell's pairs.
  // A cell's region is copied: the tree's leaf list grows (and moves) while
  // the batch fills.
  struct PendingCell {
    std::span<const std::uint32_t> items;  // when referred to
    std::span<const KeyBox> boxes;
    std::span<const std::uint8_t> below;   // the partition's below() bits, when referred to and it has them
    bool copied = false;
    std::size_t begin = 0, count = 0;      // when copied: where in the batch's items and boxes
    Cell region{};
    bool hasRegion = false;
    std::size_t splitAt = 0;
    int keep = 0;
    std::size_t deviceSplit = 0;  // non-zero: the device runs it bipartite (Backend::runBatch's split)
    std::size_t size() const { return copied ? count : boxes.size(); }
  };
  struct Batch {
    std::vector<PendingCell> cells;
    std::vector<std::uint32_t> order;     // the cells in the order the backend gets them, made at the hand-over
    std::vector<std::uint32_t> position;  // its inverse: where the backend has cell k
    std::vector<std::uint32_t> items;
    std::vector<KeyBox> boxes;
    std::vector<std::span<const KeyBox>> cellSpans;  // what the backend gets, made at the hand-over
    std::vector<std::span<const std::uint32_t>> cellItems;
    std::vector<std::size_t> splits;  // the cells' device splits, made at the hand-over; empty: none has one
    // With a narrow device: the cells' narrowed keys back to back, and the
    // spans the device gets instead of cellSpans (which decoding checks with).
    std::vector<KeyBox> narrowed;
    std::vector<std::span<const KeyBox>> narrowedSpans;
    void clear() {
      cells.clear();
      items.clear();
      boxes.clear();
    }
  };
  Batch filling;  // the batch being filled
  // Asynchronous only: the batches handed over and not yet decoded, each
  // with its answer to come and its record, used in turn; and the decoder
  // thread, which waits for each answer and decodes it while the producer
  // goes on. A slot is free again once the decoder has room for one more
  // (its tasks run in hand-over order).
  struct HandedOver {
    Batch batch;
    std::future<BatchResult> result;
    RunRecord record;
  };
  std::array<HandedOver, kBatchesInFlight> handedOver;
  std::size_t handOversThisFrame = 0;
  std::unique_ptr<SerialStage> decoder;  // Asynchronous; Polled decodes on this worker's thread
  std::size_t decodedThisFrame = 0;      // Polled: hand-overs decoded, in order
  std::vector<std::size_t> cellEnds;
  static constexpr std::size_t kSizeBuckets = 256;
  std::vector<std::uint32_t> bucketStarts;  // flush's counting sort of a batch's cells by size

  // One device cell: a partition cell or a chunk pair. `packed`: its boxes in item
  // order when the caller has them (carried tree leaves, grid cells, the whole
  // scene), else empty: they are gathered from `keys`. `lasting`: items and
  // packed stay valid until the batch is flushed, so a batch refers to them.
  // `below`: the cell's below() bits (with `lasting` only; empty: the region decides).
  // `deviceSplit`: non-zero for a bipartite run of the cell (a chunk pair's cross pairs only).
  void submit(std::span<const KeyBox> keys, std::span<const std::uint32_t> items, std::span<const KeyBox> packed,
              std::span<const std::uint8_t> below, const Cell* region, std::size_t splitAt, int keep, bool lasting,
              std::size_t deviceSplit = 0);
  void runNow(std::span<const KeyBox> keys, std::span<const std::uint32_t> items, std::span<const KeyBox> packed,
              std::span<const std::uint8_t> below, const Cell* region, std::size_t splitAt, int keep,
              std::size_t deviceSplit);
  void flush();   // hands the batch being filled over, if any
  void finish();  // flush, then (asynchronous) wait until every batch handed over is decoded
  void handOverAsynchronously(std::span<const std::span<const KeyBox>> toDevice);
  void handOverPolled(std::span<const std::span<const KeyBox>> toDevice);
  // Asynchronous and Polled: hands the batch being filled over to the device
  // in the next free slot, with its record, and takes that slot's storage.
  HandedOver& submitFilling(std::span<const std::span<const KeyBox>> toDevice, const RunRecord& record);
  // Decodes a hand-over's answer, waiting for it (its failure rethrown), and records it.
  void decodeAnswer(HandedOver& slot);
  bool polled() const { return async && !decoder; }
  // Polled: the oldest hand-over not yet decoded, polled for until it has
  // arrived; then decoded (its failure rethrown).
  void decodeOldest();
  // Polled: decodes, in order, the hand-overs whose answers have arrived.
  void decodeArrived();
  // Polled: waits out the hand-overs a failed frame left with the device,
  // whose answers nobody will decode (their batches' storage is reused).
  void abandonOutstanding();
  void startFrame(Clock::time_point start);
  // Appends a batch's kept pairs, given the backend's pairs and cell ends for it.
  void decodeBatch(const Batch& batch, std::span<const Pair> pairs, std::span<const std::size_t> ends);
  // One hand-over to the backend (`run` fills the record's counters), timed
  // and recorded for the pipeline model, then `decode` of its pairs.
  template <typename Run, typename Decode>
  void handOver(Run&& run, Decode&& decode);
  // Writes the kept pairs from `to` on (room for every one of `pairs`) and
  // returns the end. kCheckOverlap: the device compared narrowed keys, so a
  // pair is kept only where the full keys in `packed` overlap too.
  template <bool kCheckOverlap>
  static Pair* keepPairs(std::span<const Pair> pairs, std::span<const std::uint32_t> items,
                         std::span<const KeyBox> packed, std::span<const std::uint8_t> below, const Cell* region,
                         std::size_t splitAt, int keep, Pair* to);
  // Room in `out` for `hits` more pairs; the hand-over's decoding writes into
  // it, branch-free, and then cuts what it did not use (keptUntil).
  Pair* roomFor(std::size_t hits) {
    const std::size_t at = out.size();
    out.resize(at + hits);
    return out.data() + at;
  }
  void keptUntil(const Pair* end) { out.resize(static_cast<std::size_t>(end - out.data())); }
  void processCell(std::span<const KeyBox> keys, std::span<const std::uint32_t> items, std::span<const KeyBox> packed,
                   std::span<const std::uint8_t> below, const Cell* region, std::size_t capacity, bool lasting);
  bool bipartite() const { return async ? async->bipartite() : backend->bipartite(); }
  // The batch's cells as the device gets them: narrowed where it needs it.
  std::span<const std::span<const KeyBox>> deviceCells(Batch& batch);
  Pair* keepOwned(std::span<const Pair> pairs, std::span<const std::uint32_t> items, std::span<const KeyBox> packed,
                  std::span<const std::uint8_t> below, const Cell* region, std::size_t splitAt, int keep,
                  Pair* to) const {
    return narrows() ? keepPairs<true>(pairs, items, packed, below, region, splitAt, keep, to)
                     : keepPairs<false>(pairs, items, packed, below, region, splitAt, keep, to);
  }
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

std::optional<std::size_t> parseCellSize(const std::string& text) {
  if (text == "none") return std::nullopt;
  std::size_t pos = 0;
  unsigned long long v = 0;
  try {
    v = std::stoull(text, &pos);
  } catch (const std::exception&) {
    pos = 0;
  }
  if (pos != text.size() || v < 1 || text.front() == '-')
    throw std::invalid_argument(fmt::format("'{}' is neither a positive integer nor 'none'", text));
  return static_cast<std::size_t>(v);
}

std::string cellSizeName(const std::optional<std::size_t>& cellSize) {
  return cellSize ? std::to_string(*cellSize) : "none";
}

BroadPhase::BroadPhase(Backend& backend, std::optional<std::size_t> cellSize, std::size_t cellsPerBatch,
                       PartitionKind partition)
    : cellSize_(cellSize), cellsPerBatch_(cellsPerBatch), capacity_(backend.capacity()),
      partition_(makePartition(partition)) {
  auto w = std::make_unique<Worker>();
  w->backend = &backend;
  workers_.push_back(std::move(w));
  configureWorkers();
}

BroadPhase::BroadPhase(const BackendFactory& makeBackend, std::optional<std::size_t> cellSize, std::size_t threads,
                       std::size_t cellsPerBatch, PartitionKind partition, HandOvers handOvers)
    : cellSize_(cellSize), cellsPerBatch_(cellsPerBatch), handOvers_(handOvers),
      partition_(makePartition(partition)) {
  if (threads < 1) throw std::invalid_argument("broad phase: at least one thread");
  const bool async = handOvers != HandOvers::Synchronous;
  if (async && cellsPerBatch < 2)
    throw std::invalid_argument("broad phase: asynchronous hand-overs need at least two cells per batch");
  const bool polled = handOvers == HandOvers::Polled;
  for (std::size_t t = 0; t < threads; ++t) {
    auto w = std::make_unique<Worker>();
    if (async) {
      w->async = std::make_unique<AsyncBackend>(
          [&] {
            auto device = makeBackend();
            if (!device) throw std::invalid_argument("broad phase: the backend factory gave no backend");
            return device;
          },
          polled ? kDevicePollMicroseconds : std::chrono::microseconds{});
      if (!polled) w->decoder = std::make_unique<SerialStage>(kBatchesInFlight);
    } else {
      w->owned = makeBackend();
      if (!w->owned) throw std::invalid_argument("broad phase: the backend factory gave no backend");
      w->backend = w->owned.get();
    }
    workers_.push_back(std::move(w));
  }
  capacity_ = async ? workers_.front()->async->capacity() : workers_.front()->backend->capacity();
  if (threads > 1) pool_ = std::make_unique<Pool>(threads);
  configureWorkers();
}

void BroadPhase::configureWorkers() {
  check();
  for (auto& w : workers_) {
    w->cellsPerBatch = cellsPerBatch_;
    w->firstBatchCells = firstBatchCells();
    w->keyWidth = w->async ? w->async->keyWidth() : w->backend->keyWidth();
  }
}

void BroadPhase::awakenDevices() {
  if (handOvers_ != HandOvers::Polled) return;
  for (auto& w : workers_) w->async->awaken();
}

void BroadPhase::setFirstBatchCells(std::size_t cells) {
  if (cells < 1) throw std::invalid_argument("cells of the first batch must be at least 1");
  firstBatchCells_ = cells;
  configureWorkers();
}

BroadPhase::~BroadPhase() = default;

void BroadPhase::check() const {
  if (cellSize_ && *cellSize_ < 1) throw std::invalid_argument("cell size must be at least 1");
  if (capacity_ < 2) throw std::invalid_argument("backend capacity must be at least 2");
  if (cellsPerBatch_ < 1) throw std::invalid_argument("cells per batch must be at least 1");
}

void BroadPhase::findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  const auto t0 = Clock::now();
  // The bounds in the same pass when the partition will use them (timed as conversion).
  const bool withBounds = cellSize_ && partition_->needsBounds();
  KeyBounds bounds;
  if (withBounds)
    toKeys(boxes, keys_, bounds);
  else
    toKeys(boxes, keys_);
  const double convert = seconds(t0, Clock::now());
  findKeyPairs(std::span<const KeyBox>(keys_), out, withBounds ? &bounds : nullptr);
  times_.convertSeconds = convert;
  times_.totalSeconds += convert;
  for (RunRecord& r : runs_) r.readySeconds += convert;  // the conversion came first
}

void BroadPhase::findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out) { findKeyPairs(keys, out, nullptr); }

void BroadPhase::findKeyPairs(std::span<const KeyBox> keys, std::vector<Pair>& out, const KeyBounds* bounds) {
  checkObjectCount(keys.size());
  out.clear();
  stats_ = {};
  times_ = {};
  const auto t0 = Clock::now();
  startCells(t0);
  if (!cellSize_) {
    identity_.resize(keys.size());
    std::iota(identity_.begin(), identity_.end(), 0u);
    workers_.front()->processCell(keys, identity_, keys, {}, nullptr, capacity_, true);
    workers_.front()->finish();
    times_.cellsSeconds = seconds(t0, Clock::now());
  } else if (!pool_) {
    streamCells(keys, bounds);
  } else {
    streamCellsToThreads(keys, bounds);
  }
  finishCells(out);
  times_.totalSeconds = times_.partitionSeconds + times_.cellsSeconds;
}

// Each cell goes to the backend as soon as the partition has made it: the
// tree hands each leaf to a sink while it goes on (the first run is ready
// long before the tree is finished); other partitions tell when a prefix
// of their cells is final (the grid: slab by slab), and those cells are
// gone through here, with no call through a sink and no clock read per cell.
void BroadPhase::streamCells(std::span<const KeyBox> keys, const KeyBounds* bounds) {
  const auto t0 = Clock::now();
  Worker& w = *workers_.front();
  double inCells = 0;
  if (partition_->streamsCells()) {
    partition_->build(keys, *cellSize_, [&](const Cell& leaf, std::span<const std::uint32_t> items,
                                            std::span<const KeyBox> packed) {
      const auto c0 = Clock::now();
      w.processCell(keys, items, packed, {}, &leaf, capacity_, partition_->cellsOutliveBuild());
      inCells += seconds(c0, Clock::now());
    }, bounds);
  } else {
    std::size_t done = 0;
    const auto processUpTo = [&](std::size_t finalCells) {
      const auto c0 = Clock::now();
      const auto& cells = partition_->cells();
      const bool lasting = partition_->cellsOutliveBuild();
      for (; done < finalCells; ++done) {
        const Cell& cell = cells[done];
        w.processCell(keys, partition_->items(cell), partition_->packed(cell), partition_->below(cell), &cell,
                      capacity_, lasting);
      }
      inCells += seconds(c0, Clock::now());
    };
    // One reference captured: the sink fits std::function's own storage (no allocation a frame).
    partition_->buildInSteps(keys, *cellSize_, [&processUpTo](std::size_t k) { processUpTo(k); }, bounds);
  }
  const auto f0 = Clock::now();
  w.finish();  // the last, partly filled batch
  inCells += seconds(f0, Clock::now());
  times_.cellsSeconds = inCells;
  times_.partitionSeconds = seconds(t0, Clock::now()) - inCells;
}

// The calling thread builds the partition and hands each cell to the pool as
// a task while it goes on; the other threads process cells meanwhile, and the
// builder joins them when the partition is done. A task gets its own copy of
// the cell's items and boxes: the tree's storage changes as the build goes on.
void BroadPhase::streamCellsToThreads(std::span<const KeyBox> keys, const KeyBounds* bounds) {
  const auto t0 = Clock::now();
  Clock::time_point built;
  pool_->run([&] {
    tbb::task_group tasks;
    std::size_t used = 0;
    partition_->build(keys, *cellSize_, [&](const Cell& leaf, std::span<const std::uint32_t> items,
                                            std::span<const KeyBox> packed) {
      if (items.size() < 2) return;  // no pair
      if (used == cellCopies_.size()) cellCopies_.emplace_back();  // a deque: earlier copies stay put
      CellCopy& copy = cellCopies_[used++];
      copy.items.assign(items.begin(), items.end());
      copy.packed.assign(packed.begin(), packed.end());
      tasks.run([this, keys, leaf, &copy] {
        // Inside this arena, thread indices are 0 .. threads-1: one worker each.
        Worker& w = *workers_.at(static_cast<std::size_t>(tbb::this_task_arena::current_thread_index()));
        w.processCell(keys, copy.items, copy.packed, {}, &leaf, capacity_, false);
      });
    }, bounds);
    built = Clock::now();
    tasks.wait();
    // Each worker's last, partly filled batch; no task runs any more, so
    // this thread may use every worker's backend.
    for (auto& w : workers_) w->finish();
  });
  times_.partitionSeconds = seconds(t0, built);
  times_.cellsSeconds = seconds(built, Clock::now());
}

void BroadPhase::startCells(Clock::time_point frameStart) {
  for (auto& w : workers_) w->startFrame(frameStart);
}

void BroadPhase::Worker::startFrame(Clock::time_point start) {
  // Left over only if a frame failed before its end: the device and the
  // decoder must be done with those batches first (before `out` is cleared,
  // which the decoder writes). Their failure was the failed frame's.
  if (decoder) {
    try {
      decoder->drain();
    } catch (...) {
    }
  }
  if (polled()) {
    abandonOutstanding();
    async->wake();  // polling by the time the partition has the first batch
  }
  handOversThisFrame = 0;
  decodedThisFrame = 0;
  filling.clear();
  out.clear();
  stats = {};
  backendSeconds = 0;
  frameStart = start;
  runs.clear();
  batchLimit = firstBatchCells;
}

void BroadPhase::finishCells(std::vector<Pair>& out) {
  runs_.clear();
  // One worker hands its pairs over without a copy (and takes the caller's empty buffer for the next frame).
  if (workers_.size() == 1) out.swap(workers_.front()->out);
  for (auto& w : workers_) {
    if (workers_.size() > 1) out.insert(out.end(), w->out.begin(), w->out.end());
    stats_ += w->stats;
    times_.backendSeconds += w->backendSeconds;
    runs_.insert(runs_.end(), w->runs.begin(), w->runs.end());
  }
}

// A cell within capacity is one run. A larger one is cut into k chunks of at
// most capacity/2 boxes. Where the backend runs bipartite runs, each chunk
// runs alone for its inside pairs and each two chunks p < q run as one
// bipartite run for their cross pairs, so every pair is tested once; all
// of them fill batches like any cell, so a run loads while the one before
// it computes.
// Otherwise chunks p < q run together and keep their cross pairs, and each
// chunk's inside pairs are kept from exactly one run: chunk p from run
// (p, p+1), the last chunk from run (k-2, k-1); those runs test every
// chunk's inside pairs again in every pair it is in.
void BroadPhase::Worker::processCell(std::span<const KeyBox> keys, std::span<const std::uint32_t> items,
                                     std::span<const KeyBox> packed, std::span<const std::uint8_t> below,
                                     const Cell* region, std::size_t capacity, bool lasting) {
  if (items.size() < 2) return;
  if (items.size() <= capacity) {
    submit(keys, items, packed, below, region, items.size(), kFirstInside, lasting);
    return;
  }
  const std::size_t chunk = capacity / 2;
  const std::size_t k = (items.size() + chunk - 1) / chunk;
  const auto chunkOf = [&](std::size_t p) { return items.subspan(p * chunk, std::min(chunk, items.size() - p * chunk)); };
  const bool acrossOnly = bipartite();
  if (acrossOnly)
    for (std::size_t p = 0; p < k; ++p)
      if (chunkOf(p).size() >= 2) submit(keys, chunkOf(p), {}, {}, region, chunkOf(p).size(), kFirstInside, false);
  std::vector<std::uint32_t> pairItems;  // rare path (cell beyond capacity): allocation is fine here
  for (std::size_t p = 0; p < k; ++p) {
    for (std::size_t q = p + 1; q < k; ++q) {
      const auto first = chunkOf(p), second = chunkOf(q);
      pairItems.assign(first.begin(), first.end());
      pairItems.insert(pairItems.end(), second.begin(), second.end());
      if (acrossOnly) {
        submit(keys, pairItems, {}, {}, region, first.size(), kCross, false, first.size());
        continue;
      }
      int keep = kCross;
      if (q == p + 1) keep |= kFirstInside;
      if (p == k - 2 && q == k - 1) keep |= kSecondInside;
      submit(keys, pairItems, {}, {}, region, first.size(), keep, false);
    }
  }
}

void BroadPhase::Worker::submit(std::span<const KeyBox> keys, std::span<const std::uint32_t> items,
                                std::span<const KeyBox> packed, std::span<const std::uint8_t> below,
                                const Cell* region, std::size_t splitAt, int keep, bool lasting,
                                std::size_t deviceSplit) {
  if (!lasting) below = {};  // valid during the call only: the region decides
  if (cellsPerBatch <= 1) {
    runNow(keys, items, packed, below, region, splitAt, keep, deviceSplit);
    return;
  }
  PendingCell cell;
  if (region) cell.region = *region;
  cell.hasRegion = region != nullptr;
  cell.splitAt = splitAt;
  cell.keep = keep;
  cell.deviceSplit = deviceSplit;
  if (lasting && !packed.empty()) {
    cell.items = items;
    cell.boxes = packed;
    cell.below = below;
  } else {
    cell.copied = true;
    cell.begin = filling.items.size();
    cell.count = items.size();
    filling.items.insert(filling.items.end(), items.begin(), items.end());
    if (packed.empty())
      for (const std::uint32_t id : items) filling.boxes.push_back(keys[id]);
    else
      filling.boxes.insert(filling.boxes.end(), packed.begin(), packed.end());
  }
  filling.cells.push_back(cell);
  if (filling.cells.size() >= batchLimit) flush();
}

void BroadPhase::Worker::flush() {
  if (filling.cells.empty()) return;
  batchLimit = std::min(2 * batchLimit, cellsPerBatch);
  // The cells go in ascending size. A device that loads the next cell while
  // the current one runs (the stream's) hides those loads only under a run
  // about as long; in the partition's order a small cell before a large one
  // left the difference in the open (bench, 8000 boxes, grid 64: loads were
  // about 1,030 of 14,700 device cycles; in ascending size 320 of 14,000).
  // Cells decode by their own records, so any order gives the same pairs. A
  // counting sort: std::sort's mispredicted compares cost about a microsecond
  // a batch of 64.
  // Cells of kSizeBuckets - 1 boxes or more share the last bucket in the
  // partition's order, as before (the bench's cells rarely get there).
  const auto bucketOf = [](const PendingCell& c) { return std::min(c.size(), kSizeBuckets - 1); };
  bucketStarts.assign(kSizeBuckets + 1, 0);
  for (const PendingCell& c : filling.cells) ++bucketStarts[bucketOf(c) + 1];
  std::partial_sum(bucketStarts.begin(), bucketStarts.end(), bucketStarts.begin());
  filling.order.resize(filling.cells.size());
  filling.position.resize(filling.cells.size());
  for (std::size_t k = 0; k < filling.cells.size(); ++k) {
    const std::uint32_t at = bucketStarts[bucketOf(filling.cells[k])]++;
    filling.order[at] = static_cast<std::uint32_t>(k);
    filling.position[k] = at;
  }
  filling.cellSpans.clear();
  filling.cellItems.clear();
  filling.splits.clear();
  bool anySplit = false;
  for (const PendingCell& c : filling.cells) anySplit = anySplit || c.deviceSplit != 0;
  for (const std::uint32_t k : filling.order) {
    const PendingCell& c = filling.cells[k];
    if (anySplit) filling.splits.push_back(c.deviceSplit);
    filling.cellSpans.push_back(c.copied ? std::span<const KeyBox>(filling.boxes).subspan(c.begin, c.count) : c.boxes);
    filling.cellItems.push_back(c.copied ? std::span<const std::uint32_t>(filling.items).subspan(c.begin, c.count)
                                         : c.items);
  }
  // Narrowed here, before the hand-over's clock starts: it is host work.
  const auto toDevice = deviceCells(filling);
  if (!async) {
    local.clear();
    cellEnds.clear();
    handOver(
        [&](RunStats& runStats) { backend->runBatch(toDevice, filling.splits, local, cellEnds, runStats); },
        [&] { decodeBatch(filling, local, cellEnds); });
    filling.clear();
    return;
  }
  if (polled())
    handOverPolled(toDevice);
  else
    handOverAsynchronously(toDevice);
}

// The batch goes to the device and its decoding to the decoder thread, which
// waits for the device's answer; the producer goes on filling the next batch
// at once. With kBatchesInFlight batches handed over and not yet decoded, it
// waits for the oldest to be decoded, whose slot (and storage) this batch
// takes: time waiting for the device, not host work.
void BroadPhase::Worker::handOverAsynchronously(std::span<const std::span<const KeyBox>> toDevice) {
  if (decoder->failed()) {
    filling.clear();
    decoder->drain();  // rethrows the device's or the decoding's failure: the frame stops here
  }
  const auto ready = Clock::now();
  RunRecord record;
  record.readySeconds = seconds(frameStart, ready) - backendSeconds;
  decoder->waitForRoom();
  backendSeconds += seconds(ready, Clock::now());
  HandedOver& slot = submitFilling(toDevice, record);
  decoder->post([this, &slot] { decodeAnswer(slot); });
}

BroadPhase::Worker::HandedOver& BroadPhase::Worker::submitFilling(std::span<const std::span<const KeyBox>> toDevice,
                                                                  const RunRecord& record) {
  HandedOver& slot = handedOver[handOversThisFrame++ % kBatchesInFlight];
  slot.result = async->submit(toDevice, filling.splits);
  // Swapping keeps the vectors' storage, so the spans the device holds stay
  // valid; `filling` takes the decoded batch's storage.
  std::swap(filling, slot.batch);
  filling.clear();
  slot.record = record;
  return slot;
}

void BroadPhase::Worker::decodeAnswer(HandedOver& slot) {
  BatchResult result = slot.result.get();  // rethrows the device's failure
  const auto got = Clock::now();
  stats += result.stats;
  decodeBatch(slot.batch, result.pairs, result.cellEnds);
  slot.record.stats = result.stats;
  slot.record.decodeSeconds = seconds(got, Clock::now());
  runs.push_back(slot.record);
}

// The batch goes to the device, and the answers that have arrived are
// decoded here before the producer goes on; with kBatchesInFlight batches
// handed over and not yet decoded, it first polls for the oldest's answer
// (time waiting for the device, not host work) and decodes it.
void BroadPhase::Worker::handOverPolled(std::span<const std::span<const KeyBox>> toDevice) {
  RunRecord record;
  record.readySeconds = seconds(frameStart, Clock::now()) - backendSeconds;
  if (handOversThisFrame - decodedThisFrame == kBatchesInFlight) decodeOldest();
  submitFilling(toDevice, record);
  decodeArrived();
}

void BroadPhase::Worker::decodeOldest() {
  HandedOver& slot = handedOver[decodedThisFrame % kBatchesInFlight];
  const auto from = Clock::now();
  // Polled for, as the device's thread polls for hand-overs: sleeping on the
  // future would cost a wake-up when it is set. Beyond kDevicePollMicroseconds
  // (a long run, or more polling threads than cores) it sleeps after all.
  while (slot.result.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    if (Clock::now() - from > kDevicePollMicroseconds) {
      slot.result.wait();
      break;
    }
    pollPause();
  }
  backendSeconds += seconds(from, Clock::now());
  ++decodedThisFrame;  // first: a failure leaves the next one the oldest
  decodeAnswer(slot);
}

void BroadPhase::Worker::decodeArrived() {
  while (decodedThisFrame < handOversThisFrame &&
         handedOver[decodedThisFrame % kBatchesInFlight].result.wait_for(std::chrono::seconds(0)) ==
             std::future_status::ready)
    decodeOldest();
}

void BroadPhase::Worker::abandonOutstanding() {
  for (; decodedThisFrame < handOversThisFrame; ++decodedThisFrame) {
    auto& result = handedOver[decodedThisFrame % kBatchesInFlight].result;
    if (result.valid()) result.wait();
  }
}

void BroadPhase::Worker::finish() {
  flush();
  if (polled()) {
    while (decodedThisFrame < handOversThisFrame) decodeOldest();
    return;
  }
  if (!decoder) return;
  const auto waitFrom = Clock::now();
  decoder->drain();  // every batch decoded; rethrows the first failure
  backendSeconds += seconds(waitFrom, Clock::now());
}

void BroadPhase::Worker::decodeBatch(const Batch& batch, std::span<const Pair> pairs,
                                     std::span<const std::size_t> ends) {
  if (ends.size() != batch.cells.size() || (!ends.empty() && ends.back() != pairs.size()))
    throw std::logic_error(fmt::format("broad phase: backend {} returned {} cell ends for a batch of {} cells",
                                       async ? async->name() : backend->name(), ends.size(), batch.cells.size()));
  Pair* to = roomFor(pairs.size());
  // In the partition's order, not the device's: the cells' items and bits
  // are then read in the order they lie in memory.
  for (std::size_t k = 0; k < batch.cells.size(); ++k) {
    const PendingCell& cell = batch.cells[k];
    const std::size_t c = batch.position[k], from = c == 0 ? 0 : ends[c - 1];
    to = keepOwned(pairs.subspan(from, ends[c] - from), batch.cellItems[c], batch.cellSpans[c], cell.below,
                   cell.hasRegion ? &cell.region : nullptr, cell.splitAt, cell.keep, to);
  }
  keptUntil(to);
}

void BroadPhase::Worker::runNow(std::span<const KeyBox> keys, std::span<const std::uint32_t> items,
                                std::span<const KeyBox> packed, std::span<const std::uint8_t> below,
                                const Cell* region, std::size_t splitAt, int keep, std::size_t deviceSplit) {
  if (packed.empty()) {
    gathered.resize(items.size());
    for (std::size_t t = 0; t < items.size(); ++t) gathered[t] = keys[items[t]];
    packed = gathered;
  }
  std::span<const KeyBox> toDevice = packed;
  if (narrows()) {
    narrowedRun.resize(packed.size());
    narrowKeys(packed, keyWidth, narrowedRun);
    toDevice = narrowedRun;
  }
  local.clear();
  handOver(
      [&](RunStats& runStats) {
        if (deviceSplit == 0)
          backend->run(toDevice, local, runStats);
        else
          backend->runBipartite(toDevice, deviceSplit, local, runStats);
      },
      [&] { keptUntil(keepOwned(local, items, packed, below, region, splitAt, keep, roomFor(local.size()))); });
}

std::span<const std::span<const KeyBox>> BroadPhase::Worker::deviceCells(Batch& batch) {
  if (!narrows()) return batch.cellSpans;
  std::size_t total = 0;
  for (const auto& cell : batch.cellSpans) total += cell.size();
  batch.narrowed.resize(total);  // before any span into it is taken
  batch.narrowedSpans.clear();
  std::size_t at = 0;
  for (const auto& cell : batch.cellSpans) {
    const std::span<KeyBox> to(batch.narrowed.data() + at, cell.size());
    narrowKeys(cell, keyWidth, to);
    batch.narrowedSpans.emplace_back(to);
    at += cell.size();
  }
  return batch.narrowedSpans;
}

template <typename Run, typename Decode>
void BroadPhase::Worker::handOver(Run&& run, Decode&& decode) {
  RunRecord record;
  const auto ready = Clock::now();
  record.readySeconds = seconds(frameStart, ready) - backendSeconds;
  run(record.stats);
  const auto ran = Clock::now();
  backendSeconds += seconds(ready, ran);
  stats += record.stats;
  decode();
  record.decodeSeconds = seconds(ran, Clock::now());
  runs.push_back(record);
}

// Keeps the pairs of one device cell that this cell owns: the kinds `keep`
// asks for (a chunk pair's cross pairs, or the inside pairs of one chunk),
// and only those whose reference point lies in the cell's region: for a
// whole cell with the partition's below() bits, decided from two bytes
// instead of two boxes; else from the boxes (chunks pass no bits).
template <bool kCheckOverlap>
Pair* BroadPhase::Worker::keepPairs(std::span<const Pair> pairs, std::span<const std::uint32_t> items,
                                    std::span<const KeyBox> packed, std::span<const std::uint8_t> below,
                                    const Cell* region, std::size_t splitAt, int keep, Pair* to) {
  // Every pair is written and the cursor moves on only for a kept one: no
  // branch to mispredict (about a sixth of a grid cell's hits belong to
  // another cell, at random).
  const std::uint32_t* const ids = items.data();
  if (!below.empty() && keep == kFirstInside && splitAt == items.size()) {
    // One run of the whole cell: every pair is an inside pair of the first chunk.
    const std::uint8_t* const bits = below.data();
    for (const auto& [a, b] : pairs) {
      const std::uint32_t i = ids[a], j = ids[b];
      *to = {std::min(i, j), std::max(i, j)};
      if constexpr (kCheckOverlap)
        to += static_cast<int>(ownsPair(bits[a], bits[b])) & static_cast<int>(overlapsBranchFree(packed[a], packed[b]));
      else
        to += ownsPair(bits[a], bits[b]);
    }
    return to;
  }
  for (const auto& [a, b] : pairs) {
    const bool firstA = a < splitAt, firstB = b < splitAt;
    const int kind = firstA != firstB ? kCross : (firstA ? kFirstInside : kSecondInside);
    const bool owned = !region || region->contains(referencePoint(packed[a], packed[b]));
    const std::uint32_t i = ids[a], j = ids[b];
    *to = {std::min(i, j), std::max(i, j)};
    int kept = static_cast<int>((keep & kind) != 0) & static_cast<int>(owned);
    if constexpr (kCheckOverlap) kept &= static_cast<int>(overlapsBranchFree(packed[a], packed[b]));
    to += kept;
  }
  return to;
}

}  // namespace bpaccel
