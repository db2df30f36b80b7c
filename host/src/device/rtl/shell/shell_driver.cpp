#include "shell_driver.hpp"

#include <cmath>

#include <fmt/format.h>

#include "../../backend.hpp"
#include "bpaccel_shell.h"
#include "shell_probe.hpp"

namespace bpaccel {
namespace {

constexpr std::uint32_t kIrqCauses = BPACCEL_SHELL_REG_IRQ_STATUS_REPLY_MASK | BPACCEL_SHELL_REG_IRQ_STATUS_ERROR_MASK;
constexpr std::uint32_t kCommandOpen = BPACCEL_SHELL_REG_STATUS_BUSY_MASK | BPACCEL_SHELL_REG_STATUS_IN_PACKET_MASK |
                                       BPACCEL_SHELL_REG_STATUS_REPLY_OPEN_MASK;

std::chrono::microseconds remaining(std::chrono::nanoseconds deadline, std::chrono::nanoseconds now) {
  return deadline > now ? std::chrono::ceil<std::chrono::microseconds>(deadline - now) : std::chrono::microseconds{0};
}

}  // namespace

std::uint32_t ShellDriver::statusRegister() { return BPACCEL_SHELL_REG_STATUS; }

ShellDriver::ShellDriver(ShellTransport& transport, ShellDriverConfig config)
    : ShellDriver(transport, builtShellIdentity(), config) {}

ShellDriver::ShellDriver(ShellTransport& transport, const ShellIdentity& identity, ShellDriverConfig config)
    : transport_(transport), config_(config), format_(identity.format) {
  probeShell(transport_, identity);
  if ((status() & kCommandOpen) != 0) recover();  // a process died mid-command
  setUpInterrupts();
  waitReady();
}

void ShellDriver::setUpInterrupts() {
  transport_.writeRegister(BPACCEL_SHELL_REG_IRQ_STATUS, kIrqCauses);
  transport_.writeRegister(BPACCEL_SHELL_REG_IRQ_ENABLE,
                           config_.interrupts ? BPACCEL_SHELL_REG_IRQ_ENABLE_REPLY_MASK |
                                                    BPACCEL_SHELL_REG_IRQ_ENABLE_ERROR_MASK
                                              : 0u);
}

std::chrono::microseconds ShellDriver::timeoutFor(std::uint64_t coreCycles) const {
  const double us = static_cast<double>(config_.timeoutMargin) * static_cast<double>(coreCycles) /
                    config_.slowestCoreMHz;
  return config_.timeoutFloor + std::chrono::microseconds{static_cast<std::int64_t>(std::ceil(us))};
}

Trailer ShellDriver::runCells(const CellsCommand& command, std::vector<Pair>& out,
                              std::vector<std::size_t>& cellEnds) {
  encodeCells(format_, command, packet_);
  const std::size_t replyWords = cellsReplyWords(format_, command);
  // The work bound: each cell's loads, its issue cycles and a run's overheads.
  std::uint64_t work = 0;
  for (std::size_t k = 0; k < command.cells.size(); ++k)
    work += command.cells[k].size() + scheduleIssueCycles(command.cells[k].size(), format_.lanes, command.split(k)) +
            64;
  const Trailer trailer = exchange(packet_, replyWords, timeoutFor(work + packet_.size()), reply_);
  if (trailer.error != BPACCEL_SHELL_ERR_NONE) throw ShellDeviceError("CELLS", trailer);
  try {
    decodeCellsReply(format_, reply_, trailer, command, out, cellEnds);
  } catch (const ShellProtocolError&) {
    recover();  // a reply that cannot answer the command: nothing of the stream can be trusted
    throw;
  }
  return trailer;
}

Trailer ShellDriver::runFrame(std::span<const KeyBox> boxes, const FrameGrid& grid, std::size_t maxPairs,
                              std::vector<Pair>& out) {
  encodeFrame(format_, boxes, grid, packet_);
  const std::uint64_t work = boxes.size() * 16 + maxPairs + 1024;  // intake, binning passes, one pair a cycle
  const Trailer trailer = exchange(packet_, frameReplyWords(format_, maxPairs), timeoutFor(work), reply_);
  if (trailer.error != BPACCEL_SHELL_ERR_NONE) throw ShellDeviceError("FRAME", trailer);
  try {
    decodeFrameReply(format_, reply_, trailer, boxes.size(), out);
  } catch (const ShellProtocolError&) {
    recover();
    throw;
  }
  return trailer;
}

Trailer ShellDriver::exchange(std::span<const std::uint32_t> packet, std::size_t replyWords,
                              std::chrono::microseconds timeout, std::vector<std::uint32_t>& reply) {
  if (packet.empty() || packet.size() % format_.wordsPerBeat != 0)
    throw std::invalid_argument(fmt::format("shell: a packet of {} words is not whole beats of {} words",
                                            packet.size(), format_.wordsPerBeat));
  transport_.postReceive(replyWords);  // before the send: the reply may start while the packet streams in
  transport_.send(packet);
  ++events_.commands;
  if (!awaitReply(timeout, reply)) {
    ++events_.timeouts;
    const bool inStep = abortCommand(reply);
    throw ShellTimeout(fmt::format("shell: no reply within {} us to a command of {} words; the driver aborted it{}",
                                   timeout.count(), packet.size(),
                                   inStep ? "" : " and reset the shell (the abort left the streams out of step)"));
  }
  try {
    const Trailer trailer = decodeTrailer(format_, reply);
    const std::uint32_t opcode = packet[0] & 0xFFu;
    if (trailer.opcode != opcode)
      throw ShellProtocolError(fmt::format("shell: the reply is to opcode {:#x}, the command was {:#x}",
                                           trailer.opcode, opcode));
    return trailer;
  } catch (const ShellProtocolError& e) {
    recover();
    if (reply.size() == replyWords)  // a full buffer: the DMA cut the reply
      throw ShellProtocolError(fmt::format("{} (the reply filled the {} words posted for it: it was longer)",
                                           e.what(), replyWords));
    throw;
  }
}

bool ShellDriver::awaitReply(std::chrono::microseconds timeout, std::vector<std::uint32_t>& reply) {
  const std::chrono::nanoseconds deadline = transport_.now() + timeout;
  if (config_.interrupts) {
    // No interrupt: a reply cut by a full buffer completes the receive without its trailer leaving the shell.
    if (!transport_.waitInterrupt(timeout)) return transport_.receive(reply, std::chrono::microseconds{0});
    acknowledgeInterrupt();
  }
  // With interrupts the reply has left the shell already; a DMA engine may still be finishing its write.
  return transport_.receive(reply, std::max(remaining(deadline, transport_.now()), std::chrono::microseconds{1}));
}

void ShellDriver::acknowledgeInterrupt() {
  const std::uint32_t causes = transport_.readRegister(BPACCEL_SHELL_REG_IRQ_STATUS);
  transport_.writeRegister(BPACCEL_SHELL_REG_IRQ_STATUS, causes);  // W1C: the line falls
  events_.lastIrqStatus = causes;
  ++events_.interrupts;
}

bool ShellDriver::abortCommand(std::vector<std::uint32_t>& reply) {
  transport_.writeRegister(BPACCEL_SHELL_REG_CONTROL, BPACCEL_SHELL_REG_CONTROL_ABORT_MASK);
  ++events_.aborts;
  // The reply ends with ABORTED at once, even if the packet never ends; the
  // stream is in step only if the rest of the packet came and was drained.
  if (transport_.receive(reply, config_.abortTimeout) && waitClosed()) {
    transport_.writeRegister(BPACCEL_SHELL_REG_IRQ_STATUS, kIrqCauses);
    return true;
  }
  recover();
  return false;
}

void ShellDriver::recover() {
  transport_.resetChannels();
  transport_.writeRegister(BPACCEL_SHELL_REG_CONTROL, BPACCEL_SHELL_REG_CONTROL_SOFT_RESET_MASK);
  ++events_.recoveries;
  waitReady();
  transport_.writeRegister(BPACCEL_SHELL_REG_IRQ_STATUS, kIrqCauses);
}

bool ShellDriver::waitClosed() {
  // STATUS follows the trailer's TLAST by a few bus cycles, and the rest of an aborted packet may still be coming.
  const std::chrono::nanoseconds deadline = transport_.now() + config_.abortTimeout;
  while ((status() & kCommandOpen) != 0)
    if (transport_.now() > deadline) return false;
  return true;
}

void ShellDriver::waitReady() {
  const std::chrono::nanoseconds deadline = transport_.now() + config_.readyTimeout;
  while ((status() & BPACCEL_SHELL_REG_STATUS_READY_MASK) == 0)
    if (transport_.now() > deadline)
      throw ShellProtocolError(
          fmt::format("shell: STATUS.READY still 0 after {} us", config_.readyTimeout.count()));
}

}  // namespace bpaccel
