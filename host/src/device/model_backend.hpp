#pragma once
// The cycle-exact C++ model of a generated device.

#include <span>
#include <string>
#include <vector>

#include "backend.hpp"
#include "device_params.hpp"

namespace bpaccel {

/// Fast C++ model of the accelerator: the same schedule, pairs and cycle
/// counts (loads included) as the RTL behind its shell (CELLS commands, which
/// feed the core's batch port a box a cycle) with a consumer that never
/// stalls, for any n up to its capacity and at software speed. Both architectures share the schedule and differ only
/// in the cycles before the first issue (DeviceParams::startupCycles).
/// Batches of up to batchCells cells cost what the hardware's front end adds:
/// one cycle per batch and one per cell; with batchOverlapsLoads each cell
/// loads while the one before runs, so its load cycles are only those no run hides.
class ModelBackend final : public Backend {
 public:
  /// Throws std::invalid_argument for parameters no device has (DeviceParams::check).
  explicit ModelBackend(const DeviceParams& params);
  const DeviceParams& params() const { return params_; }
  std::string name() const override { return "model"; }
  std::size_t capacity() const override { return params_.capacity; }
  unsigned keyWidth() const override { return params_.keyWidth; }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override;
  using Backend::runBatch;
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override;
  /// Where the device has them (DeviceParams::bipartiteRuns: the stream architecture's).
  bool bipartite() const override { return params_.bipartiteRuns; }

 private:
  /// One cell's pairs and counters (split 0: all pairs), without counting it
  /// as a run; its load cycles and cycles depend on the hand-over (run, or batchCycles).
  void runCell(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats) const;
  /// One cell as its own run and hand-over: runCell plus the cycles of a batch of that one cell.
  void runSplit(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats) override;
  /// All busy cycles of a run of n objects.
  std::uint64_t busyCycles(std::uint64_t n, std::uint64_t split = 0) const;
  /// One hardware batch's load and run cycles, cell by cell on the device's
  /// timeline (`splits`: one per cell, or empty).
  void batchCycles(std::span<const std::span<const KeyBox>> batch, std::span<const std::size_t> splits,
                   RunStats& stats) const;

  DeviceParams params_;
};

}  // namespace bpaccel
