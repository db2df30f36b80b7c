#pragma once
// One way to reach a shell (docs/integration.md, "The host's driver and its
// transports"): its AXI4-Lite registers, its two AXI4-Stream channels and
// its interrupt line. A Verilated model, a PCIe card with XDMA, VFIO: each
// is one transport, and the driver (ShellDriver) is the same over all.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace bpaccel {

class ShellTransport {
 public:
  virtual ~ShellTransport() = default;

  /// One 32-bit read of the register at byte `offset` (a BAR read; an AXI4-Lite read).
  virtual std::uint32_t readRegister(std::uint32_t offset) = 0;
  /// One 32-bit write, all byte lanes.
  virtual void writeRegister(std::uint32_t offset, std::uint32_t value) = 0;

  /// Posts a buffer of `maxWords` words for the next reply (a C2H or S2MM
  /// descriptor): the device's output moves only while one is posted. Replies
  /// fill posted buffers in order; a reply longer than its buffer is received
  /// truncated to the buffer, as a DMA engine would, so receive() reports it
  /// as a reply of exactly maxWords words.
  virtual void postReceive(std::size_t maxWords) = 0;
  /// Queues one packet (whole beats) on the input channel, TLAST on its last
  /// beat. May return before the packet is sent; the transport keeps its copy.
  virtual void send(std::span<const std::uint32_t> packet) = 0;
  /// Waits up to `timeout` for the oldest posted receive to complete (its
  /// TLAST, or its buffer full); on completion replaces `reply` with its
  /// words and returns true.
  virtual bool receive(std::vector<std::uint32_t>& reply, std::chrono::microseconds timeout) = 0;
  /// Waits up to `timeout` for the interrupt line to be high; returns whether it is.
  virtual bool waitInterrupt(std::chrono::microseconds timeout) = 0;
  /// Halts and flushes both channels: packets not yet sent (also one half
  /// sent), posted receives and what they hold. Before a soft reset.
  virtual void resetChannels() = 0;
  /// The transport's clock, for the driver's polls: wall time on a card,
  /// simulated time on a model.
  virtual std::chrono::nanoseconds now() = 0;
};

}  // namespace bpaccel
