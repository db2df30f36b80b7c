#pragma once
// The device interface: all pairs over one run, or over a batch of cells,
// of at most capacity() boxes each.

#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "../core/all_pairs_kernel.hpp"
#include "../core/types.hpp"

namespace bpaccel {

class Backend;
/// Makes a backend: for a thread, or a device thread, of its own.
using BackendFactory = std::function<std::unique_ptr<Backend>()>;

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
  /// The kernel of a backend that is software on the host's own cores (the
  /// cpu backend): the broad phase then runs its cells itself, on its
  /// threads, reading each cell's boxes from the frame's keys and keeping
  /// only the pairs a cell owns (no hand-over, no decoding). Null for a device.
  virtual const AllPairsKernel* hostKernel() const { return nullptr; }
  /// Whether runBipartite() exists here (the stream architecture's device and its model).
  virtual bool bipartite() const { return false; }
  /// One bipartite run (one run, one batch): appends only the overlapping
  /// pairs (i, j) with i < split <= j, for 1 <= split < boxes.size(). Where
  /// bipartite() is false it throws std::logic_error (checkBipartite), else runs runSplit.
  void runBipartite(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats);

 protected:
  /// For backends with bipartite runs: one run of `boxes` with `split` (one
  /// runBipartite has checked). By default throws std::logic_error.
  virtual void runSplit(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats);
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

/// The accelerator's schedule in closed form: issue cycles of one run of n
/// objects with m lanes, sum over blocks b of (n - 1 - b*m); 0 for n < 2.
/// A bipartite run (split = na > 0) runs the blocks b*m <= na-1 only, in
/// min(n - 1 - b*m, 2m - 1 + n - na) cycles each. Must equal
/// bpaccel.Schedule.issueCycles in the generator (tests compare it with the
/// Verilated hardware's own counter).
std::uint64_t scheduleIssueCycles(std::uint64_t n, std::uint64_t m, std::uint64_t split = 0);

}  // namespace bpaccel
