#pragma once
// A ShellTransport without hardware, for the driver's unit tests: registers
// that hold the built shell's values, replies from a plain reference device
// (reference_shell.hpp) or scripted by the test, and a log of every call.

#include <algorithm>
#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bpaccel_shell.h"
#include "device/rtl/shell/shell_probe.hpp"
#include "device/rtl/shell/shell_transport.hpp"
#include "reference_shell.hpp"

namespace bpaccel::testing {

class FakeShellTransport final : public ShellTransport {
 public:
  FakeShellTransport() {
    regs[BPACCEL_SHELL_REG_ID] = BPACCEL_SHELL_REG_ID_RESET;
    regs[BPACCEL_SHELL_REG_VERSION] = BPACCEL_SHELL_REG_VERSION_RESET;
    regs[BPACCEL_SHELL_REG_FINGERPRINT] = BPACCEL_SHELL_FINGERPRINT;
    for (const ExpectedRegister& r : builtShellIdentity().capabilities) regs[r.offset] = r.value;
    regs[BPACCEL_SHELL_REG_STATUS] = BPACCEL_SHELL_REG_STATUS_READY_MASK;
  }

  // What the device does with a packet: by default, the reference device's reply.
  std::function<std::vector<std::uint32_t>(const std::vector<std::uint32_t>&)> answer =
      [](const std::vector<std::uint32_t>& packet) { return referenceCellsReply(builtShellIdentity().format, packet); };
  int silentCommands = 0;       // the next commands get no reply (a hang)
  bool answersAbort = true;     // CONTROL.ABORT of a silent command gives an ABORTED trailer
  bool abortLeavesInPacket = false;  // ... with STATUS.IN_PACKET still set
  int readyAfterReads = 2;      // STATUS reads with READY low after a soft reset

  std::map<std::uint32_t, std::uint32_t> regs;
  std::vector<std::string> log;
  std::vector<std::vector<std::uint32_t>> sent;

  std::uint32_t readRegister(std::uint32_t offset) override {
    time_ += std::chrono::microseconds{1};
    log.push_back(fmt::format("read {:#x}", offset));
    if (offset == BPACCEL_SHELL_REG_STATUS && notReadyReads_ > 0) {
      --notReadyReads_;
      return regs[offset] & ~BPACCEL_SHELL_REG_STATUS_READY_MASK;
    }
    return regs[offset];
  }

  void writeRegister(std::uint32_t offset, std::uint32_t value) override {
    time_ += std::chrono::microseconds{1};
    log.push_back(fmt::format("write {:#x} {:#x}", offset, value));
    if (offset == BPACCEL_SHELL_REG_IRQ_STATUS) {
      regs[offset] &= ~value;
    } else if (offset == BPACCEL_SHELL_REG_CONTROL && (value & BPACCEL_SHELL_REG_CONTROL_ABORT_MASK)) {
      if (hung_ > 0 && answersAbort) {
        --hung_;
        ReferenceTrailer t;
        t.error = BPACCEL_SHELL_ERR_ABORTED;
        deliver(packReply(builtShellIdentity().format, {}, t));
        if (abortLeavesInPacket) regs[BPACCEL_SHELL_REG_STATUS] |= BPACCEL_SHELL_REG_STATUS_IN_PACKET_MASK;
      }
    } else if (offset == BPACCEL_SHELL_REG_CONTROL && (value & BPACCEL_SHELL_REG_CONTROL_SOFT_RESET_MASK)) {
      regs[BPACCEL_SHELL_REG_STATUS] = BPACCEL_SHELL_REG_STATUS_READY_MASK;
      notReadyReads_ = readyAfterReads;
      hung_ = 0;
    } else {
      regs[offset] = value;
    }
  }

  void postReceive(std::size_t maxWords) override {
    log.push_back(fmt::format("post {}", maxWords));
    posted_.push_back(maxWords);
  }

  void send(std::span<const std::uint32_t> packet) override {
    log.push_back(fmt::format("send {}", packet.size()));
    sent.emplace_back(packet.begin(), packet.end());
    if (silentCommands > 0) {
      --silentCommands;
      ++hung_;
      return;
    }
    deliver(answer(sent.back()));
  }

  bool receive(std::vector<std::uint32_t>& reply, std::chrono::microseconds timeout) override {
    log.push_back("receive");
    if (replies_.empty() || posted_.empty()) {
      time_ += timeout;
      return false;
    }
    reply = std::move(replies_.front());
    replies_.pop_front();
    if (reply.size() > posted_.front()) reply.resize(posted_.front());  // the DMA stops at its buffer's end
    posted_.pop_front();
    return true;
  }

  bool waitInterrupt(std::chrono::microseconds timeout) override {
    log.push_back("wait interrupt");
    if ((regs[BPACCEL_SHELL_REG_IRQ_STATUS] & regs[BPACCEL_SHELL_REG_IRQ_ENABLE]) != 0) return true;
    time_ += timeout;
    return false;
  }

  void resetChannels() override {
    log.push_back("reset channels");
    replies_.clear();
    posted_.clear();
  }

  std::chrono::nanoseconds now() override { return time_; }

  /// How many entries of the log are `entry`.
  std::size_t count(const std::string& entry) const {
    return static_cast<std::size_t>(std::count(log.begin(), log.end(), entry));
  }

 private:
  void deliver(std::vector<std::uint32_t> reply) {
    const std::uint32_t error = reply[reply.size() - BPACCEL_SHELL_TRAILER_WORDS] >> 8 & 0xFFu;
    regs[BPACCEL_SHELL_REG_IRQ_STATUS] |=
        BPACCEL_SHELL_REG_IRQ_STATUS_REPLY_MASK | (error != 0 ? BPACCEL_SHELL_REG_IRQ_STATUS_ERROR_MASK : 0u);
    replies_.push_back(std::move(reply));
  }

  std::deque<std::vector<std::uint32_t>> replies_;
  std::deque<std::size_t> posted_;
  std::chrono::nanoseconds time_{0};
  int notReadyReads_ = 0;
  int hung_ = 0;  // commands sent that got no reply yet
};

/// Log entries for register accesses, by offset.
inline std::string readOf(std::uint32_t offset) { return fmt::format("read {:#x}", offset); }
inline std::string writeOf(std::uint32_t offset, std::uint32_t value) {
  return fmt::format("write {:#x} {:#x}", offset, value);
}

}  // namespace bpaccel::testing
