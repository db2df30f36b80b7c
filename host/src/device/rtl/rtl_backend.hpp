#pragma once
// The Verilated accelerator as a Backend.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "../backend.hpp"
#include "../built_device.hpp"

class VBroadPhaseAccel;
class VerilatedContext;

namespace bpaccel {

/// Drives the generated hardware cycle by cycle through its load port, start
/// command and result port, and reports the hardware's own counters. The
/// configuration comes from bpaccel_params.h, and the constructor checks it
/// against the model's info port.
class RtlBackend final : public Backend {
 public:
  /// `consumerReady(cycle)` is the result consumer's ready pattern; by default
  /// it is always ready, like a host that drains a FIFO at full rate.
  explicit RtlBackend(std::function<bool(std::uint64_t)> consumerReady = {});
  ~RtlBackend() override;
  RtlBackend(const RtlBackend&) = delete;
  RtlBackend& operator=(const RtlBackend&) = delete;

  std::string name() const override { return "rtl"; }
  std::size_t capacity() const override;
  /// On any failure (a hang, a hardware error) the device is reset before the
  /// exception leaves, so the next run starts from an idle accelerator.
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override;
  /// Pushes the cells' counts (and splits) on the batch port and streams
  /// their boxes, one a cycle, as hardware batches of at most batchCells()
  /// cells each. On any failure the device is reset and nothing of the call
  /// is left in `out`, `cellEnds` or `stats`.
  using Backend::runBatch;
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override;
  /// BPACCEL_BIPARTITE_RUNS: the stream architecture's hardware.
  bool bipartite() const override;
  unsigned keyWidth() const override;

  static std::size_t lanes();
  static std::size_t batchCells();
  /// "seed" or "stream": the architecture this host was built with.
  static std::string architecture();
  static std::uint64_t runOverheadCycles();

 private:
  void settle();  // evaluate combinational outputs for the current inputs
  void tick();    // one rising clock edge
  void reset();
  /// One start with the split (0: all pairs); on any failure the device is
  /// reset before the exception leaves, as in run().
  void runSplit(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats) override;
  void runOnHardware(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats);
  void batchOnHardware(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                       std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats);

  std::unique_ptr<VerilatedContext> context_;
  std::unique_ptr<VBroadPhaseAccel> top_;
  std::function<bool(std::uint64_t)> consumerReady_;
};

/// The backend `name` ("rtl", "model" or "cpu") of the hardware this host was
/// built with (builtDeviceParams); throws std::invalid_argument for another name.
std::unique_ptr<Backend> makeBuiltBackend(const std::string& name);

}  // namespace bpaccel
