#pragma once
// A whole-scene broad phase: keys, an optional partition (k-d tree or grid),
// device cells, hand-overs to one device per thread, decoding.

#include <chrono>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "../device/backend.hpp"
#include "../partition/partition.hpp"
#include "broad_phase_config.hpp"
#include "frame_observer.hpp"

namespace bpaccel {

class Worker;

/// Finds every overlapping pair of a scene exactly once. Without a cell size
/// the scene is one cell. A cell larger than the device's capacity is covered
/// in chunks (planChunks). The scene is partitioned into cells by a k-d tree
/// or a uniform grid (BroadPhaseConfig::partition), and each cell goes to the
/// device as soon as the partition has made it: the tree hands each over while
/// it goes on, the grid slab by slab once its items are placed. With several
/// threads, the calling thread builds the partition and the cells are shared
/// out among workers as tasks, each worker with a device of its own from the
/// factory (devices keep scratch state and are not shared between threads).
///
/// With cellsPerBatch > 1 each worker adds the cells it is given, packed, to
/// the batch it is filling (referring to the partition's storage where it
/// outlives the batch, as the grid's does; else copying) and hands it over
/// when it holds that many cells, and at the end of the frame. One batch is
/// one hand-over to the device (one link latency).
class BroadPhase {
 public:
  /// One thread, synchronous hand-overs, on `backend` (which must outlive it).
  explicit BroadPhase(Backend& backend, const BroadPhaseConfig& config = {});
  /// config.threads workers, each with a device of its own from `makeBackend`.
  explicit BroadPhase(const BackendFactory& makeBackend, const BroadPhaseConfig& config = {});
  ~BroadPhase();
  BroadPhase(const BroadPhase&) = delete;
  BroadPhase& operator=(const BroadPhase&) = delete;

  /// Appends the pairs (i < j, unsorted) to `out` (cleared first).
  void findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);
  /// The same on boxes already converted to keys.
  void findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out);

  const BroadPhaseConfig& config() const { return config_; }
  /// The last call's device counters.
  const RunStats& stats() const { return stats_; }
  /// The last call's cells (with a cell size).
  const Partition& partition() const { return *partition_; }
  std::size_t threads() const { return workers_.size(); }
  /// Polled hand-overs: returns once every worker's device thread is awake
  /// and polling for the next hand-over (for kDevicePollMicroseconds). Where
  /// the device stands for a card, which needs no waking, a caller that times
  /// a frame calls it first; findPairs wakes them too, but without waiting.
  /// Does nothing with other hand-overs.
  void awakenDevices();

 private:
  class Pool;
  using Clock = std::chrono::steady_clock;
  BroadPhase(const BroadPhaseConfig& config, const std::function<std::unique_ptr<Worker>()>& makeWorker);
  // `bounds`: the keys' bounds when the conversion found them, else null.
  void findKeyPairs(std::span<const KeyBox> keys, std::vector<Pair>& out, const KeyBounds* bounds);
  // One thread: partition and cells interleaved.
  void streamCells(std::span<const KeyBox> keys, const KeyBounds* bounds);
  // The pool: cells as tasks while the partition goes on.
  void streamCellsToThreads(std::span<const KeyBox> keys, const KeyBounds* bounds);
  void finishCells(std::vector<Pair>& out);  // gathers the workers' results
  Clock::time_point now() const;              // a clock read only where an observer wants the timing

  BroadPhaseConfig config_;
  std::vector<std::unique_ptr<Worker>> workers_;
  std::unique_ptr<Pool> pool_;  // only with more than one worker
  std::size_t capacity_ = 0;
  std::unique_ptr<Partition> partition_;
  std::vector<KeyBox> keys_;
  std::vector<std::uint32_t> identity_;  // 0..n-1: the scene as one cell
  struct CellCopy {
    std::vector<std::uint32_t> items;
    std::vector<KeyBox> packed;
  };
  std::deque<CellCopy> cellCopies_;  // the pool's copies of cells, kept between frames
  RunStats stats_;
  FrameTiming timing_;  // with an observer: the frame being timed
};

}  // namespace bpaccel
