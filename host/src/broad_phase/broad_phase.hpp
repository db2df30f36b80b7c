#pragma once
// A whole-scene broad phase: keys, optional partition (k-d tree or grid), chunking, backend runs.

#include <algorithm>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "../device/backend.hpp"
#include "hand_over_record.hpp"
#include "../partition/partition.hpp"
#include "../core/types.hpp"

namespace bpaccel {

/// Host time of one findPairs call, by part (measured with a steady clock).
struct HostTimes {
  double convertSeconds = 0;  // float to key conversion and validation
  double partitionSeconds = 0;  // partition build (k-d tree or grid, with the grid's packing of its cells'
                                // boxes), without the cells' processing
  double cellsSeconds = 0;    // packing, backend runs, decoding and filtering
  double backendSeconds = 0;  // inside Backend::run (simulating the device, or the cpu test itself),
                              // summed over the worker threads
  double totalSeconds = 0;    // all of the above (conversion only when the input was floats)
};

/// How a worker hands its batches to the backend: waiting for each
/// (Synchronous), or as a pipeline of three threads (Asynchronous; only
/// with the factory constructor and cellsPerBatch > 1): the worker's
/// thread fills batches and hands each over to an AsyncBackend, which runs
/// the worker's backend on a thread of its own, and goes on at once; a
/// decoder thread (SerialStage) waits for each batch's answer and decodes
/// it. At most kBatchesInFlight batches are handed over and not yet
/// decoded; the worker waits for the oldest before it hands over one more.
/// This is the schedule modelPipeline models.
///
/// Polled: two threads, where a card would leave one. The device runs on a
/// thread of its own as with Asynchronous, and that thread polls for the
/// next hand-over (AsyncBackend's spinBeforeSleep, kDevicePollMicroseconds)
/// as a card takes a doorbell; the worker's thread decodes the answers
/// itself: after each hand-over it decodes those that have arrived, and it
/// polls (spins) for an answer it must have: for room (kBatchesInFlight) and
/// at the frame's end. No thread waits to be woken during a frame, which on
/// the virtual machines here cost 22-62 us a wake-up, but each polling
/// thread takes a core. modelPipeline models it with
/// PipelineModel::decodeOnProducer.
///
/// The pairs (in the same order), the counters and the hand-overs are the
/// same in all three.
enum class HandOvers { Synchronous, Asynchronous, Polled };

/// How long a polled device's thread (HandOvers::Polled) polls for the next
/// hand-over after each one before it sleeps: longer than the gaps between a
/// frame's hand-overs here (up to about 0.1 ms), short enough that it sleeps
/// between frames.
inline constexpr std::chrono::microseconds kDevicePollMicroseconds{250};

/// Finds every overlapping pair of a scene exactly once. Without a cell size
/// the scene is one cell. A cell larger than the backend's capacity is
/// covered in chunks of capacity/2 boxes: where the backend runs bipartite
/// runs (Backend::bipartite), each chunk runs alone and every two chunks run
/// as one bipartite run, so each pair is tested once; otherwise every two
/// chunks run together, and each pair is kept from exactly one of those runs.
///
/// The scene is partitioned into cells by a k-d tree (the default) or a
/// uniform grid (PartitionKind). The cells go to the backend as the
/// partition makes them: the tree hands each over while it goes on, the
/// grid slab by slab once its items are placed (Partition::buildInSteps).
/// With several threads, the calling thread builds the partition and the cells are
/// shared out among workers as tasks, each worker with a backend of its own
/// from the factory (backends keep scratch state and are not shared between
/// threads).
///
/// `cellsPerBatch` > 1 hands cells to the backend in batches
/// (Backend::runBatch): each worker adds the cells it is given, packed, to
/// the batch it is filling (referring to the partition's storage where it
/// outlives the batch, as the grid's does; else copying) and hands it over
/// when it holds that many cells, and at the end of the frame. One batch is one hand-over to the
/// device (one link latency). With 1, each cell is handed over on its own,
/// straight from the partition's storage.
/// "none" (no partition: the scene is one cell) or a positive integer, as the
/// command lines spell a cell size; throws std::invalid_argument naming the text otherwise.
std::optional<std::size_t> parseCellSize(const std::string& text);
/// The same spelling of a cell size ("none" or the number).
std::string cellSizeName(const std::optional<std::size_t>& cellSize);

class BroadPhase {
 public:
  using BackendFactory = std::function<std::unique_ptr<Backend>()>;

  /// One thread, on `backend`.
  BroadPhase(Backend& backend, std::optional<std::size_t> cellSize, std::size_t cellsPerBatch = 1,
             PartitionKind partition = PartitionKind::KdTree);
  /// `threads` workers (at least 1), each with its own backend.
  BroadPhase(const BackendFactory& makeBackend, std::optional<std::size_t> cellSize, std::size_t threads,
             std::size_t cellsPerBatch = 1, PartitionKind partition = PartitionKind::KdTree,
             HandOvers handOvers = HandOvers::Synchronous);
  ~BroadPhase();
  BroadPhase(const BroadPhase&) = delete;
  BroadPhase& operator=(const BroadPhase&) = delete;

  /// Appends the pairs (i < j, unsorted) to `out` (cleared first).
  void findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);
  /// The same on boxes already converted to keys.
  void findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out);

  const RunStats& stats() const { return stats_; }
  const HostTimes& times() const { return times_; }
  /// The last call's cells (with a cell size).
  const Partition& partition() const { return *partition_; }
  std::size_t threads() const { return workers_.size(); }
  std::size_t cellsPerBatch() const { return cellsPerBatch_; }
  /// Slow start: a frame's first hand-over holds at most `cells` cells (at
  /// least 1), and each next one twice as many as the one before, up to
  /// cellsPerBatch. The device gets its first cells as soon as the partition
  /// has made a few, instead of after a whole batch's worth, and is kept busy
  /// from then on while the host fills the growing batches. By default every
  /// hand-over holds cellsPerBatch cells.
  void setFirstBatchCells(std::size_t cells);
  std::size_t firstBatchCells() const {
    return firstBatchCells_ ? std::min(firstBatchCells_, cellsPerBatch_) : cellsPerBatch_;
  }
  HandOvers handOvers() const { return handOvers_; }
  /// Polled hand-overs: returns once every worker's device thread is awake
  /// and polling for the next hand-over (for kDevicePollMicroseconds).
  /// Where the device stands for a card, which needs no waking, a caller
  /// that times a frame calls it first; findPairs wakes them too, but
  /// without waiting. Does nothing with other hand-overs.
  void awakenDevices();
  /// The last call's hand-overs to the backend (batches, or single runs) in
  /// order, with the measured host time at which each was ready and its
  /// decoding took (for modelPipeline). With several threads, each worker's
  /// hand-overs follow the previous worker's.
  const std::vector<RunRecord>& runs() const { return runs_; }

 private:
  struct Worker;
  class Pool;
  // `bounds`: the keys' bounds when the conversion found them, else null.
  void findKeyPairs(std::span<const KeyBox> keys, std::vector<Pair>& out, const KeyBounds* bounds);
  // One thread: partition and cells interleaved.
  void streamCells(std::span<const KeyBox> keys, const KeyBounds* bounds);
  // The pool: cells as tasks while the partition goes on.
  void streamCellsToThreads(std::span<const KeyBox> keys, const KeyBounds* bounds);
  void startCells(std::chrono::steady_clock::time_point frameStart);  // clears the workers' results
  void finishCells(std::vector<Pair>& out);                            // gathers them
  void check() const;
  void configureWorkers();

  std::vector<std::unique_ptr<Worker>> workers_;
  std::unique_ptr<Pool> pool_;  // only with more than one worker
  std::optional<std::size_t> cellSize_;
  std::size_t cellsPerBatch_;
  std::size_t firstBatchCells_ = 0;  // 0: cellsPerBatch_
  HandOvers handOvers_ = HandOvers::Synchronous;
  std::size_t capacity_;
  std::unique_ptr<Partition> partition_;
  std::vector<KeyBox> keys_;
  std::vector<std::uint32_t> identity_;  // 0..n-1: the scene as one cell
  struct CellCopy {
    std::vector<std::uint32_t> items;
    std::vector<KeyBox> packed;
  };
  std::deque<CellCopy> cellCopies_;  // the pool's copies of cells, kept between frames
  RunStats stats_;
  HostTimes times_;
  std::vector<RunRecord> runs_;
};

}  // namespace bpaccel
