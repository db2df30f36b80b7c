#pragma once
// The Verilated device as a Backend: the shell around the core, driven by
// the shell's driver over the Verilated transport.

#include <cstdint>
#include <functional>
#include <memory>

#include "../backend.hpp"
#include "../built_device.hpp"
#include "shell/shell_driver.hpp"
#include "verilated_shell_transport.hpp"

namespace bpaccel {

struct RtlBackendConfig {
  VerilatedShellConfig shell;   // clocks, and the streams' ready patterns
  ShellDriverConfig driver;     // interrupts or polling, timeouts
};

/// Runs cells on the Verilated shell (BpaccelShell with its core) through
/// ShellDriver: each hand-over is CELLS commands of at most batchCells()
/// cells, a real driver's register sequence and interrupt handling, and the
/// counters are each reply's trailer. The configuration comes from
/// bpaccel_params.h and bpaccel_shell.h, which the driver's probe checks
/// against the model's registers.
class RtlBackend final : public Backend {
 public:
  /// `replyReady(cycle)` is the reply channel's TREADY pattern; by default it
  /// is always ready, like a DMA engine with buffers posted.
  explicit RtlBackend(std::function<bool(std::uint64_t)> replyReady = {});
  explicit RtlBackend(RtlBackendConfig config);
  ~RtlBackend() override;
  RtlBackend(const RtlBackend&) = delete;
  RtlBackend& operator=(const RtlBackend&) = delete;

  std::string name() const override { return "rtl"; }
  std::size_t capacity() const override;
  /// One cell: a CELLS command of one cell (the shell has no other start).
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override;
  /// CELLS commands of at most batchCells() cells each, one after the other.
  /// Bad input throws before anything reaches the device; on any failure
  /// nothing of the call is left in `out`, `cellEnds` or `stats`, and the
  /// device is ready for the next call (the driver aborts or resets it).
  using Backend::runBatch;
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override;
  /// BPACCEL_BIPARTITE_RUNS: the stream architecture's hardware.
  bool bipartite() const override;
  unsigned keyWidth() const override;

  /// The driver and the transport, for tests of the shell.
  ShellDriver& driver() { return *driver_; }
  VerilatedShellTransport& transport() { return *transport_; }

  static std::size_t lanes();
  static std::size_t batchCells();
  /// "seed" or "stream": the architecture this host was built with.
  static std::string architecture();
  static std::uint64_t runOverheadCycles();

 private:
  void runSplit(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out, RunStats& stats) override;
  /// Throws, before the device sees anything, for cells it would refuse.
  void checkCells(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits) const;
  void runCommands(const CellsCommand& all, std::vector<Pair>& out, std::vector<std::size_t>& cellEnds,
                   RunStats& stats);

  std::unique_ptr<VerilatedShellTransport> transport_;
  std::unique_ptr<ShellDriver> driver_;
};

/// The backend `name` ("rtl", "model" or "cpu") of the hardware this host was
/// built with (builtDeviceParams); throws std::invalid_argument for another name.
std::unique_ptr<Backend> makeBuiltBackend(const std::string& name);

}  // namespace bpaccel
