#pragma once
// The members of VerilatedShellTransportOf<Top>, for the one translation
// unit that instantiates it for its Verilated model (after including the
// model's header).

#include <algorithm>
#include <type_traits>

#include <fmt/format.h>

#include "shell/shell_reply.hpp"
#include "verilated.h"
#include "verilated_shell_transport.hpp"

namespace bpaccel::verilated_shell {

constexpr std::uint32_t kSlaveError = 2;             // AXI4-Lite SLVERR
constexpr std::uint64_t kRegisterAccessCycles = 1000;  // far above the register bank's few cycles

// 32-bit words of a port, whatever type Verilator chose for its width: an
// integer up to 64 bits, else VlWide<words>.
template <typename T>
struct PortWords {
  static_assert(std::is_integral_v<T> && sizeof(T) == 8, "a TDATA of one integer is a 64-bit stream");
  static constexpr unsigned value = 2;
};
template <std::size_t N>
struct PortWords<VlWide<N>> {
  static constexpr unsigned value = N;
};
template <class Top>
constexpr unsigned kWords = PortWords<std::remove_cvref_t<decltype(std::declval<Top&>().s_axis_tdata)>>::value;
// Whether the shell has a core clock of its own (emitted with --dual-clock true).
template <class Top>
constexpr bool kDualClock = requires(Top& top) { top.core_clk; };

// A beat's words into TDATA.
template <unsigned Words, typename T>
void putBeat(T& port, const std::uint32_t* words) {
  if constexpr (std::is_integral_v<T>) {
    port = words[0] | static_cast<std::uint64_t>(words[1]) << 32;
  } else {
    for (unsigned i = 0; i < Words; ++i) port[i] = words[i];
  }
}

template <unsigned Words, typename T>
void takeBeat(const T& port, std::vector<std::uint32_t>& into) {
  if constexpr (std::is_integral_v<T>) {
    into.push_back(static_cast<std::uint32_t>(port));
    into.push_back(static_cast<std::uint32_t>(static_cast<std::uint64_t>(port) >> 32));
  } else {
    for (unsigned i = 0; i < Words; ++i) into.push_back(port[i]);
  }
}

}  // namespace bpaccel::verilated_shell

namespace bpaccel {

template <class Top>
VerilatedShellTransportOf<Top>::VerilatedShellTransportOf(VerilatedShellConfig config)
    : config_(std::move(config)),
      context_(std::make_unique<VerilatedContext>()),
      top_(std::make_unique<Top>(context_.get(), "shell")) {
  if (config_.busPeriodPs < 2 || config_.busPeriodPs % 2 != 0 || config_.corePeriodPs < 2 ||
      config_.corePeriodPs % 2 != 0)
    throw std::invalid_argument(fmt::format("verilated shell: clock periods of {} and {} ps (even, at least 2)",
                                            config_.busPeriodPs, config_.corePeriodPs));
  nextBusEdge_ = config_.busPeriodPs / 2;
  nextCoreEdge_ = config_.corePeriodPs / 2;
  top_->aresetn = 0;
  // One aclk edge before core_clk's first: Verilator starts every register at
  // 0, which reads as a core side out of reset with its state unset; this
  // edge raises the reset request that holds the core side (asynchronously).
  top_->aclk = 0;
  top_->eval();
  top_->aclk = 1;
  top_->eval();
  top_->aclk = 0;
  top_->eval();
  for (int i = 0; i < 8; ++i) cycle();
  top_->aresetn = 1;
  cycle();
}

template <class Top>
VerilatedShellTransportOf<Top>::~VerilatedShellTransportOf() { top_->final(); }

template <class Top>
bool VerilatedShellTransportOf<Top>::interruptLine() const { return top_->irq != 0; }

template <class Top>
std::chrono::nanoseconds VerilatedShellTransportOf<Top>::now() {
  return std::chrono::nanoseconds{counters_.busCycles * config_.busPeriodPs / 1000};
}

template <class Top>
std::uint64_t VerilatedShellTransportOf<Top>::cyclesOf(std::chrono::microseconds timeout) const {
  return static_cast<std::uint64_t>(timeout.count()) * 1'000'000u / config_.busPeriodPs;
}

template <class Top>
void VerilatedShellTransportOf<Top>::cycle() {
  driveInputs();
  // The handshakes of this edge: the shell's outputs are flip-flops, set at the last rise of aclk.
  const bool sent = offering_ && top_->s_axis_tready;
  const bool replied = top_->m_axis_tready && top_->m_axis_tvalid;
  if (replied) takeReplyBeat();  // TDATA as it stands before the edge
  if (!top_->m_axis_tready && top_->m_axis_tvalid) ++counters_.replyStallCycles;
  const bool addressed = read_.address && top_->s_axil_arready;
  const bool read = read_.response && !read_.address && top_->s_axil_rvalid;
  if (read) read_.rdata = top_->s_axil_rdata, read_.resp = top_->s_axil_rresp;
  const bool writeAddressed = write_.address && top_->s_axil_awready;
  const bool written = write_.data && top_->s_axil_wready;
  const bool answered = write_.response && !write_.address && !write_.data && top_->s_axil_bvalid;
  if (answered) write_.resp = top_->s_axil_bresp;

  clockToNextBusRise();
  ++counters_.busCycles;

  if (sent) {
    offering_ = false;
    sendAt_ += verilated_shell::kWords<Top>;
    ++counters_.beatsSent;
    if (sendAt_ == packetEnds_.front()) packetEnds_.pop_front();
    if (sendAt_ == sendWords_.size()) sendWords_.clear(), sendAt_ = 0;
  }
  if (addressed) read_.address = false;
  if (read) read_.response = false;
  if (writeAddressed) write_.address = false;
  if (written) write_.data = false;
  if (answered) write_.response = false;
  const bool irq = top_->irq != 0;
  counters_.interruptRises += irq && !irqWas_;
  irqWas_ = irq;
}

template <class Top>
void VerilatedShellTransportOf<Top>::driveInputs() {
  const std::uint64_t now = counters_.busCycles;
  if (!offering_ && sendAt_ < sendWords_.size() && (!config_.sendReady || config_.sendReady(now))) {
    offering_ = true;
    verilated_shell::putBeat<verilated_shell::kWords<Top>>(top_->s_axis_tdata, sendWords_.data() + sendAt_);
    top_->s_axis_tlast = sendAt_ + verilated_shell::kWords<Top> == packetEnds_.front();
  }
  top_->s_axis_tvalid = offering_;
  top_->m_axis_tready = !posted_.empty() && (!config_.replyReady || config_.replyReady(now));
  top_->s_axil_arvalid = read_.address;
  top_->s_axil_rready = read_.response;
  top_->s_axil_awvalid = write_.address;
  top_->s_axil_wvalid = write_.data;
  top_->s_axil_bready = write_.response;
}

template <class Top>
void VerilatedShellTransportOf<Top>::clockToNextBusRise() {
  // Each eval handles the edges due at one instant: both clocks' at once where they coincide.
  for (;;) {
    const std::uint64_t t = verilated_shell::kDualClock<Top> ? std::min(nextBusEdge_, nextCoreEdge_) : nextBusEdge_;
    bool busRose = false;
    if (nextBusEdge_ == t) {
      busHigh_ = !busHigh_;
      top_->aclk = busHigh_;
      busRose = busHigh_;
      nextBusEdge_ += config_.busPeriodPs / 2;
    }
    if constexpr (verilated_shell::kDualClock<Top>) {
      if (nextCoreEdge_ == t) {
        coreHigh_ = !coreHigh_;
        top_->core_clk = coreHigh_;
        nextCoreEdge_ += config_.corePeriodPs / 2;
      }
    }
    top_->eval();
    if (busRose) return;
  }
}

template <class Top>
void VerilatedShellTransportOf<Top>::takeReplyBeat() {
  ++counters_.beatsReceived;
  verilated_shell::takeBeat<verilated_shell::kWords<Top>>(top_->m_axis_tdata, current_);
  // A reply ends at TLAST, or where its buffer is full (the rest goes to the next one, as a DMA engine does).
  if (top_->m_axis_tlast || current_.size() >= posted_.front()) {
    completed_.push_back(std::move(current_));
    current_.clear();
    posted_.pop_front();
  }
}

template <class Top>
void VerilatedShellTransportOf<Top>::complete(LiteAccess& access, const char* what, std::uint32_t offset) {
  for (std::uint64_t n = 0; access.address || access.data || access.response; ++n) {
    if (n > verilated_shell::kRegisterAccessCycles)
      throw ShellProtocolError(fmt::format("verilated shell: no AXI4-Lite {} response for offset {:#x} in {} cycles",
                                           what, offset, verilated_shell::kRegisterAccessCycles));
    cycle();
  }
  if (access.resp == verilated_shell::kSlaveError)
    throw ShellProtocolError(fmt::format("verilated shell: the {} of offset {:#x} answered SLVERR", what, offset));
}

template <class Top>
std::uint32_t VerilatedShellTransportOf<Top>::readRegister(std::uint32_t offset) {
  top_->s_axil_araddr = offset;
  read_ = {.address = true, .response = true};
  complete(read_, "read", offset);
  return read_.rdata;
}

template <class Top>
void VerilatedShellTransportOf<Top>::writeRegister(std::uint32_t offset, std::uint32_t value) {
  top_->s_axil_awaddr = offset;
  top_->s_axil_wdata = value;
  top_->s_axil_wstrb = 0xF;
  write_ = {.address = true, .data = true, .response = true};
  complete(write_, "write", offset);
}

template <class Top>
void VerilatedShellTransportOf<Top>::postReceive(std::size_t maxWords) {
  posted_.push_back(std::max<std::size_t>((maxWords + verilated_shell::kWords<Top> - 1) / verilated_shell::kWords<Top> * verilated_shell::kWords<Top>, verilated_shell::kWords<Top>));
}

template <class Top>
void VerilatedShellTransportOf<Top>::send(std::span<const std::uint32_t> packet) {
  if (packet.empty() || packet.size() % verilated_shell::kWords<Top> != 0)
    throw std::invalid_argument(
        fmt::format("verilated shell: a packet of {} words is not whole beats of {}", packet.size(), verilated_shell::kWords<Top>));
  sendWords_.insert(sendWords_.end(), packet.begin(), packet.end());
  packetEnds_.push_back(sendWords_.size());
}

template <class Top>
bool VerilatedShellTransportOf<Top>::receive(std::vector<std::uint32_t>& reply, std::chrono::microseconds timeout) {
  const std::uint64_t end = counters_.busCycles + cyclesOf(timeout);
  while (completed_.empty() && counters_.busCycles < end) cycle();
  if (completed_.empty()) return false;
  reply.swap(completed_.front());
  completed_.pop_front();
  return true;
}

template <class Top>
bool VerilatedShellTransportOf<Top>::waitInterrupt(std::chrono::microseconds timeout) {
  const std::uint64_t end = counters_.busCycles + cyclesOf(timeout);
  while (!top_->irq && counters_.busCycles < end) cycle();
  return top_->irq != 0;
}

template <class Top>
void VerilatedShellTransportOf<Top>::resetChannels() {
  sendWords_.clear();
  packetEnds_.clear();
  sendAt_ = 0;
  offering_ = false;
  posted_.clear();
  current_.clear();
  completed_.clear();
  ++counters_.channelResets;
  cycle();  // TVALID and TREADY fall
}

}  // namespace bpaccel
