#pragma once
// The binning device's RTL as a FrameDevice: the Verilated binning shell
// (BpaccelShell around BinningCore, verilated as VBinningShell) driven
// through the shell driver's FRAME command, as a card's driver drives it.

#include <memory>
#include <string>

#include "../../binning/frame_device.hpp"
#include "../shell/shell_driver.hpp"
#include "../shell/shell_identity.hpp"
#include "../verilated_shell_transport.hpp"

class VBinningShell;

namespace bpaccel {

extern template class VerilatedShellTransportOf<VBinningShell>;

struct RtlFrameDeviceConfig {
  VerilatedShellConfig shell;  // clocks, and the streams' ready patterns
  ShellDriverConfig driver;    // interrupts or polling, timeouts
};

/// One FRAME command a runFrame: the driver encodes the boxes, the shell
/// hands them to the binning core, the driver decodes the reply's pairs.
/// The reply's error, detail, pairs and counters are the trailer's; the
/// trailer carries no entry counts or phases, so `entries`, `fullestGroup`
/// and every phase but `intake` stay 0. Its cycles include the pace at which
/// the shell's stream delivers boxes, so they are at least the model's.
/// The configuration is the binning shell this library was built with
/// (builtFrameShellIdentity, builtFrameShellParams).
class RtlFrameDevice final : public FrameDevice {
 public:
  /// Builds the model, probes it and waits for READY.
  explicit RtlFrameDevice(RtlFrameDeviceConfig config = {});
  ~RtlFrameDevice() override;
  RtlFrameDevice(const RtlFrameDevice&) = delete;
  RtlFrameDevice& operator=(const RtlFrameDevice&) = delete;

  std::string name() const override { return "binning-rtl"; }
  const BinningParams& params() const override { return params_; }
  /// A frame the device refuses comes back with its error and detail. The
  /// driver sends no frame of more boxes than the capacity or of a grid
  /// dimension outside 1 .. 2^cellBits: those come back with the header
  /// error the device would send (COUNT_OVER_CAPACITY, BAD_GRID; no box can
  /// come before them) and no cycles. A key wider than the device's, or a
  /// header n other than the boxes given, throws std::invalid_argument.
  FrameReply runFrame(const FrameCommand& command) override;

  ShellDriver& driver() { return *driver_; }
  VerilatedShellTransportOf<VBinningShell>& transport() { return *transport_; }

 private:
  BinningParams params_;
  std::unique_ptr<VerilatedShellTransportOf<VBinningShell>> transport_;
  std::unique_ptr<ShellDriver> driver_;
};

/// The binning shell this library was built with (BPACCEL_FRAME_SHELL_DIR):
/// its identity for the probe, and its core's parameters.
ShellIdentity builtFrameShellIdentity();
BinningParams builtFrameShellParams();

/// The FrameError of a shell's error code (docs/protocol.md); std::invalid_argument for a code FRAME never sends.
FrameError frameErrorOfShellCode(std::uint32_t code);

}  // namespace bpaccel
