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
#include "../partition/automatic_choice.hpp"
#include "broad_phase_config.hpp"
#include "frame_observer.hpp"

namespace bpaccel {

class BinningFrame;
class FrameDevice;
class HostFrame;
class Worker;

/// Finds every overlapping pair of a scene exactly once. With a cell size of
/// none the scene is one cell. A cell larger than the device's capacity is covered
/// in chunks (planChunks). The scene is partitioned into cells by a k-d tree
/// or a uniform grid (BroadPhaseConfig::partition), and each cell goes to the
/// device as soon as the partition has made it: the tree hands each over while
/// it goes on, the grid slab by slab once its items are placed. With several
/// threads, the calling thread builds the partition and the cells are shared
/// out among workers as tasks, each worker with a device of its own from the
/// factory (devices keep scratch state and are not shared between threads).
///
/// On a backend that is software on the host (Backend::hostKernel(): the
/// cpu backend) with synchronous hand-overs, the broad phase runs the cells
/// itself (HostFrame): conversion, partition and cells on config.threads
/// threads, cellsPerBatch unused.
///
/// With an automatic cell size (the default), the partition (unless one is
/// named) and the cell size are chosen frame by frame (AutomaticChoice).
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
  /// On a binning device (which must outlive it): the device partitions the
  /// scene itself; the host sends each box once and rechecks the pairs
  /// (BinningFrame). One thread, synchronous; the config's partition, cell
  /// size and batches do not apply. Only float boxes (the host quantizes them
  /// onto the frame's grid): findPairs on keys throws std::logic_error.
  explicit BroadPhase(FrameDevice& device, const BroadPhaseConfig& config = {});
  ~BroadPhase();
  BroadPhase(const BroadPhase&) = delete;
  BroadPhase& operator=(const BroadPhase&) = delete;

  /// Appends the pairs (i < j, unsorted) to `out` (cleared first).
  void findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);
  /// The same on boxes already converted to keys.
  void findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out);

  const BroadPhaseConfig& config() const { return config_; }
  /// The last call's device counters (on the host: cells run, pairs found).
  const RunStats& stats() const;
  /// The last call's cells (with a cell size).
  const Partition& partition() const;
  /// The last call's partition and cell size (the chosen ones when automatic).
  const CellChoice& choice() const;
  std::size_t threads() const;
  /// Polled hand-overs: returns once every worker's device thread is awake
  /// and polling for the next hand-over (for kDevicePollMicroseconds). Where
  /// the device stands for a card, which needs no waking, a caller that times
  /// a frame calls it first; findPairs wakes them too, but without waiting.
  /// Does nothing with other hand-overs.
  void awakenDevices();

 private:
  class Pool;
  using Clock = std::chrono::steady_clock;
  // The device's path: one worker a thread, each from `makeWorker`.
  void startWorkers(const std::function<std::unique_ptr<Worker>()>& makeWorker);
  // Partition and cell size for this frame, and the partition that makes them.
  void chooseCells(std::size_t objects, const KeyBounds* bounds);
  // `bounds`: the keys' bounds when the conversion found them, else null.
  void findKeyPairs(std::span<const KeyBox> keys, std::vector<Pair>& out, const KeyBounds* bounds);
  // One thread: partition and cells interleaved.
  void streamCells(std::span<const KeyBox> keys, const KeyBounds* bounds);
  // The pool: cells as tasks while the partition goes on.
  void streamCellsToThreads(std::span<const KeyBox> keys, const KeyBounds* bounds);
  void finishCells(std::vector<Pair>& out);  // gathers the workers' results
  Clock::time_point now() const;              // a clock read only where an observer wants the timing

  BroadPhaseConfig config_;
  std::unique_ptr<HostFrame> host_;  // the cpu backend's path; else the workers below
  std::unique_ptr<BinningFrame> binning_;  // the binning device's path
  std::vector<std::unique_ptr<Worker>> workers_;
  std::unique_ptr<Pool> pool_;  // only with more than one worker
  std::size_t capacity_ = 0;
  std::unique_ptr<Partition> tree_, grid_;
  Partition* partition_ = nullptr;  // this frame's: tree_ or grid_
  AutomaticChoice chooser_;
  CellChoice choice_;
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
