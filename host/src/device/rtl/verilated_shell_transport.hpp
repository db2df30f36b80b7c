#pragma once
// A Verilated shell (BpaccelShell) as a ShellTransport: the transport
// clocks the model and plays the DMA engine on its two streams and the CPU
// on its registers, as a PCIe card's XDMA and its host would. One template
// for every Verilated shell: the stream width and the clocks come from the
// model's ports.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "shell/shell_transport.hpp"

class VBpaccelShell;
class VerilatedContext;

namespace bpaccel {

struct VerilatedShellConfig {
  /// Simulated clock periods in picoseconds: the bus (aclk: streams and
  /// registers) and, where the shell has two clocks, the core (core_clk).
  /// Timeouts are in simulated time at these clocks.
  std::uint64_t busPeriodPs = 4000;   // 250 MHz, a PCIe core's user clock
  std::uint64_t corePeriodPs = 4000;
  /// The reply channel's TREADY in each bus cycle (whether the C2H engine
  /// takes a beat); empty: always, while a receive is posted.
  std::function<bool(std::uint64_t cycle)> replyReady;
  /// Whether the send channel offers its next beat in this bus cycle (asked
  /// only when it has a beat and is not holding one out); empty: always.
  std::function<bool(std::uint64_t cycle)> sendReady;
};

/// What the transport saw, for tests.
struct VerilatedShellCounters {
  std::uint64_t busCycles = 0;
  std::uint64_t beatsSent = 0;
  std::uint64_t beatsReceived = 0;
  std::uint64_t replyStallCycles = 0;  // cycles the shell offered a reply beat the channel did not take
  std::uint64_t interruptRises = 0;    // rising edges of irq
  std::uint64_t channelResets = 0;
};

/// `Top`: the Verilated model's class (VBpaccelShell, ...). Instantiated
/// where the model is built (verilated_shell_transport_impl.hpp).
template <class Top>
class VerilatedShellTransportOf final : public ShellTransport {
 public:
  /// Builds the model and holds aresetn low for a few bus cycles.
  explicit VerilatedShellTransportOf(VerilatedShellConfig config = {});
  ~VerilatedShellTransportOf() override;
  VerilatedShellTransportOf(const VerilatedShellTransportOf&) = delete;
  VerilatedShellTransportOf& operator=(const VerilatedShellTransportOf&) = delete;

  std::uint32_t readRegister(std::uint32_t offset) override;
  void writeRegister(std::uint32_t offset, std::uint32_t value) override;
  void postReceive(std::size_t maxWords) override;
  void send(std::span<const std::uint32_t> packet) override;
  bool receive(std::vector<std::uint32_t>& reply, std::chrono::microseconds timeout) override;
  bool waitInterrupt(std::chrono::microseconds timeout) override;
  void resetChannels() override;
  std::chrono::nanoseconds now() override;

  const VerilatedShellCounters& counters() const { return counters_; }
  bool interruptLine() const;
  /// Bus cycles of `timeout` at the configured bus clock.
  std::uint64_t cyclesOf(std::chrono::microseconds timeout) const;

 private:
  /// One AXI4-Lite access in flight: which channels still owe a handshake.
  struct LiteAccess {
    bool address = false, data = false, response = false;
    std::uint32_t rdata = 0, resp = 0;
  };
  /// One bus cycle: the channels' and the CPU's signals, then the clock edges up to aclk's next rise.
  void cycle();
  void driveInputs();
  void clockToNextBusRise();
  void takeReplyBeat();
  /// Runs cycles until `access` has its response; throws ShellProtocolError naming `what` after too many.
  void complete(LiteAccess& access, const char* what, std::uint32_t offset);

  VerilatedShellConfig config_;
  std::unique_ptr<VerilatedContext> context_;
  std::unique_ptr<Top> top_;
  VerilatedShellCounters counters_;
  // Simulated time (ps) of each clock's next edge.
  std::uint64_t nextBusEdge_ = 0, nextCoreEdge_ = 0;
  bool busHigh_ = false, coreHigh_ = false, irqWas_ = false;
  // The send channel: packets in one buffer; where each ends; the next beat; whether it is offered.
  std::vector<std::uint32_t> sendWords_;
  std::deque<std::size_t> packetEnds_;
  std::size_t sendAt_ = 0;
  bool offering_ = false;
  // The receive channel: posted buffers' sizes, the reply being written, completed replies.
  std::deque<std::size_t> posted_;
  std::vector<std::uint32_t> current_;
  std::deque<std::vector<std::uint32_t>> completed_;
  LiteAccess read_, write_;
};

/// The shell of the core this host was built for.
extern template class VerilatedShellTransportOf<VBpaccelShell>;
using VerilatedShellTransport = VerilatedShellTransportOf<VBpaccelShell>;

}  // namespace bpaccel
