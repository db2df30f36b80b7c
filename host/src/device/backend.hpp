#pragma once
// The broad-phase backend interface: all-pairs over one batch of boxes.

#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "../core/all_pairs_kernel.hpp"
#include "../core/types.hpp"

namespace bpaccel {

/// Loads up to capacity() boxes, runs, and returns every overlapping pair
/// (indices into the batch, i < j) with the run's statistics.
class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  /// Most boxes one run takes; larger sets are chunked by BroadPhase.
  virtual std::size_t capacity() const = 0;
  /// Appends the overlapping pairs of `boxes` to `out` and adds to `stats`
  /// (one run, one batch).
  virtual void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) = 0;
  /// Runs several cells, each at most capacity() boxes: appends each cell's
  /// pairs (indices local to that cell, i < j) to `out` in cell order and
  /// pushes out.size() onto `cellEnds` after each cell. `splits` is empty
  /// (every cell all-pairs) or holds one split per cell: 0 for all pairs, or
  /// na in 1 .. n-1 for a bipartite run of that cell (see runBipartite; only
  /// where bipartite()). `stats.runs` counts the cells; `stats.batches` the
  /// hand-overs to the device. By default each cell is its own run (and so
  /// its own batch).
  virtual void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                        std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats);
  /// Every cell all-pairs.
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::vector<Pair>& out,
                std::vector<std::size_t>& cellEnds, RunStats& stats) {
    runBatch(cells, {}, out, cellEnds, stats);
  }
  /// Bits of each key the device compares (BPACCEL_KEY_WIDTH), at most 32.
  /// Below 32 a caller narrows each cell's keys first (narrowKeys) and
  /// checks the pairs it gets back with the full keys, as BroadPhase does;
  /// keys wider than this are refused, never cut.
  virtual unsigned keyWidth() const { return 32; }
  /// Whether runBipartite() exists here (the stream architecture's device and its model).
  virtual bool bipartite() const { return false; }
  /// One bipartite run (one run, one batch): appends only the overlapping
  /// pairs (i, j) with i < split <= j, for 1 <= split < boxes.size(). Where
  /// bipartite() is false it throws std::logic_error.
  virtual void runBipartite(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                            RunStats& stats);

 protected:
  /// For implementations of runBipartite: throws unless bipartite() and 1 <= split < n.
  void checkBipartite(std::size_t n, std::size_t split) const;
  /// For implementations: throws std::invalid_argument, naming the box, when
  /// a key of `boxes` does not fit keyWidth() bits (nothing to check at 32).
  void checkKeyWidth(std::span<const KeyBox> boxes) const;
  /// For implementations of runBatch: throws unless `splits` is empty or one
  /// per cell, each 0 or a split checkBipartite allows.
  void checkSplits(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits) const;
  /// Cell k's split in runBatch's `splits` (empty: every cell all-pairs, 0).
  static std::size_t splitOf(std::span<const std::size_t> splits, std::size_t k) {
    return splits.empty() ? 0 : splits[k];
  }
  /// The splits of cells [first, first + count) (empty stays empty).
  static std::span<const std::size_t> splitsOf(std::span<const std::size_t> splits, std::size_t first,
                                               std::size_t count) {
    return splits.empty() ? splits : splits.subspan(first, count);
  }
};

/// Bytes of one box on a device's load port: six keys of `keyWidth` bits (the link model's box).
constexpr std::size_t loadBoxBytes(unsigned keyWidth) { return (6 * std::size_t{keyWidth} + 7) / 8; }

/// The accelerator's schedule in closed form: issue cycles of one run of n
/// objects with m lanes, sum over blocks b of (n - 1 - b*m); 0 for n < 2.
/// A bipartite run (split = na > 0) runs the blocks b*m <= na-1 only, in
/// min(n - 1 - b*m, 2m - 1 + n - na) cycles each. Must equal
/// bpaccel.Schedule.issueCycles in the generator (tests compare it with the
/// Verilated hardware's own counter).
std::uint64_t scheduleIssueCycles(std::uint64_t n, std::uint64_t m, std::uint64_t split = 0);

/// Fast C++ model of the accelerator: the same schedule, pairs and cycle
/// counts (loads included) as the RTL driven by a host that loads one box a
/// cycle and a consumer that never stalls, for any n up to its capacity and
/// at software speed. Both architectures share the schedule and differ only
/// in the cycles before the first issue: none for the seed's; for the
/// stream's, streamReadLatency (BPACCEL_READ_LATENCY, 0 for
/// the seed's, so passing the header's values always models the hardware built).
/// Batches of up to `batchCells` cells (BPACCEL_BATCH_CELLS) cost what the
/// hardware's front end adds: one cycle per batch and one per cell; with
/// `overlapsLoads` (BPACCEL_BATCH_OVERLAPS_LOADS) each cell loads while the
/// one before runs, so its load cycles are only those no run hides.
class ModelBackend final : public Backend {
 public:
  ModelBackend(std::size_t m, std::size_t capacity, std::uint64_t runOverheadCycles,
               std::uint64_t streamReadLatency = 0, std::size_t batchCells = 64, bool overlapsLoads = false,
               unsigned keyWidth = 32);
  std::string name() const override { return "model"; }
  std::size_t capacity() const override { return capacity_; }
  unsigned keyWidth() const override { return keyWidth_; }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override;
  using Backend::runBatch;
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override;
  /// The stream architecture's (streamReadLatency > 0); the seed's hardware refuses a split.
  bool bipartite() const override { return streamReadLatency_ != 0; }
  void runBipartite(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                    RunStats& stats) override;

 private:
  /// One cell's pairs and counters (split 0: all pairs), without counting it
  /// as a run; its load cycles and cycles depend on the hand-over (run, or batchCycles).
  void runCell(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats) const;
  /// One cell as its own run and hand-over: runCell plus its loads and busy cycles.
  void runAlone(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats) const;
  /// Cycles before a run of n objects issues (0 for the seed), and all its busy cycles.
  std::uint64_t startupCycles(std::uint64_t n) const;
  std::uint64_t busyCycles(std::uint64_t n, std::uint64_t split = 0) const;
  /// One hardware batch's load and run cycles, cell by cell on the device's
  /// timeline (`splits`: one per cell, or empty).
  void batchCycles(std::span<const std::span<const KeyBox>> batch, std::span<const std::size_t> splits,
                   RunStats& stats) const;

  std::size_t m_;
  std::size_t capacity_;
  std::uint64_t overhead_;
  std::uint64_t streamReadLatency_;  // 0: the seed architecture
  std::size_t batchCells_;
  bool overlapsLoads_;
  unsigned keyWidth_;
};

/// Software alone: all pairs of the batch with SIMD compares (AllPairsKernel),
/// no capacity limit. One instance per thread: it keeps scratch space.
class CpuBackend final : public Backend {
 public:
  std::string name() const override { return "cpu"; }
  std::size_t capacity() const override { return std::numeric_limits<std::size_t>::max(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override;
  std::string_view isa() const { return kernel_.isa(); }

 private:
  AllPairsKernel kernel_;
  AllPairsKernel::Scratch scratch_;
};

}  // namespace bpaccel
