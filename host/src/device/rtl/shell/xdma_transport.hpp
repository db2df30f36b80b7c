#pragma once
// The shell on a PCIe card behind Xilinx's XDMA (AXI4-Stream mode), through
// the character devices of Xilinx's XDMA Linux driver (docs/integration.md,
// "Connecting it"): the BAR of the AXI4-Lite registers, one H2C and one C2H
// channel, and the user interrupt's event file.
//
// UNTESTED ON HARDWARE. No card was at hand: this transport was only run
// against regular files standing in for the character devices (the
// register offsets and byte order, the packet's bytes, the replies' words;
// host/tests/device/rtl/shell/xdma_transport_test.cpp). What it assumes of
// the XDMA driver is as Xilinx documents it and unverified here: a C2H read
// in streaming mode returns at TLAST (or a full buffer); a read of the
// events file blocks until the user interrupt and returns its count; a
// transfer that hangs returns an error after the driver's own timeout
// (module parameters h2c_timeout, c2h_timeout).

#include <chrono>
#include <cstdint>
#include <deque>
#include <future>
#include <string>
#include <vector>

#include "shell_transport.hpp"

namespace bpaccel {

struct XdmaPaths {
  std::string user = "/dev/xdma0_user";          // the BAR that maps the shell's AXI4-Lite window
  std::string h2c = "/dev/xdma0_h2c_0";          // host to card: s_axis
  std::string c2h = "/dev/xdma0_c2h_0";          // card to host: m_axis
  std::string events = "/dev/xdma0_events_0";    // usr_irq_req[0]: the shell's irq
  std::uint64_t registerBase = 0;                // byte offset of the shell's registers in the BAR
};

/// A file descriptor, closed on destruction.
class FileDescriptor {
 public:
  FileDescriptor(const std::string& path, int flags);
  ~FileDescriptor();
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

class XdmaTransport final : public ShellTransport {
 public:
  /// Opens the four files; throws std::system_error naming the one that fails.
  explicit XdmaTransport(XdmaPaths paths = {});
  /// Waits for transfers still in flight (each ends by the XDMA driver's timeout at the latest).
  ~XdmaTransport() override;

  std::uint32_t readRegister(std::uint32_t offset) override;
  void writeRegister(std::uint32_t offset, std::uint32_t value) override;
  /// Starts the C2H read of up to maxWords words on a thread of its own.
  void postReceive(std::size_t maxWords) override;
  /// Writes the packet to the H2C channel on a thread of its own (the
  /// transfer ends the packet with TLAST); returns at once.
  void send(std::span<const std::uint32_t> packet) override;
  bool receive(std::vector<std::uint32_t>& reply, std::chrono::microseconds timeout) override;
  bool waitInterrupt(std::chrono::microseconds timeout) override;
  /// Waits for every transfer in flight to end and drops what they bring.
  void resetChannels() override;
  std::chrono::nanoseconds now() override;

 private:
  XdmaPaths paths_;
  FileDescriptor user_, h2c_, c2h_, events_;
  std::deque<std::future<std::vector<std::uint32_t>>> receives_;
  std::deque<std::future<void>> sends_;
};

}  // namespace bpaccel
