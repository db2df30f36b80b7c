#pragma once
// The shell's driver (docs/integration.md, "One frame, as the driver does
// it"): the register sequence and the stream protocol over any transport.

#include <chrono>
#include <cstdint>
#include <span>
#include <vector>

#include "../../../core/types.hpp"
#include "cells_codec.hpp"
#include "frame_codec.hpp"
#include "shell_format.hpp"
#include "shell_identity.hpp"
#include "shell_reply.hpp"
#include "shell_transport.hpp"

namespace bpaccel {

struct ShellDriverConfig {
  /// Wait for the interrupt line (IRQ_ENABLE.REPLY and ERROR), acknowledge it,
  /// then take the reply; else (IRQ_ENABLE 0) wait for the receive alone.
  bool interrupts = true;
  /// A command's timeout: this floor plus `timeoutMargin` times its work at
  /// `slowestCoreMHz` (a bound on the core cycles it can take without stalls).
  std::chrono::microseconds timeoutFloor{2000};
  double slowestCoreMHz = 10.0;
  unsigned timeoutMargin = 4;
  /// How long the ABORTED reply may take after CONTROL.ABORT, and READY after a soft reset.
  std::chrono::microseconds abortTimeout{500};
  std::chrono::microseconds readyTimeout{500};
};

/// What the driver has done since it probed, for logs and tests.
struct ShellDriverEvents {
  std::uint64_t commands = 0;      // commands sent
  std::uint64_t interrupts = 0;    // interrupts taken (IRQ_STATUS read and acknowledged)
  std::uint64_t timeouts = 0;      // commands without a reply in time
  std::uint64_t aborts = 0;        // CONTROL.ABORT writes
  std::uint64_t recoveries = 0;    // soft resets
  std::uint32_t lastIrqStatus = 0; // IRQ_STATUS as the last interrupt found it
};

/// Drives one shell through a transport: the shell of `identity`, by default
/// the one this program was built for (builtShellIdentity). Not thread-safe:
/// one thread issues commands, one at a time.
class ShellDriver {
 public:
  /// Probes the shell (ID, VERSION, the capability registers and FINGERPRINT
  /// against `identity`; throws ShellProbeError naming the first
  /// difference), recovers it if a command was left open, sets up its
  /// interrupts and waits for READY.
  ShellDriver(ShellTransport& transport, const ShellIdentity& identity, ShellDriverConfig config = {});
  explicit ShellDriver(ShellTransport& transport, ShellDriverConfig config = {});

  /// The layout of the shell's packets (as probed).
  const ShellFormat& format() const { return format_; }
  const ShellDriverEvents& events() const { return events_; }

  /// One CELLS command: appends each cell's pairs (indices within the cell,
  /// in record order) to `out` and pushes out.size() onto `cellEnds` after
  /// each cell; returns the trailer. Throws std::invalid_argument, before
  /// anything reaches the device, for a command it would refuse;
  /// ShellDeviceError for an error trailer; ShellTimeout; ShellProtocolError.
  /// After any of them `out` and `cellEnds` are as they were and the shell
  /// is ready for the next command.
  Trailer runCells(const CellsCommand& command, std::vector<Pair>& out, std::vector<std::size_t>& cellEnds);
  /// One FRAME command (the binning device), `maxPairs` records at most
  /// (a reply that does not fit is a ShellProtocolError); as runCells.
  Trailer runFrame(std::span<const KeyBox> boxes, const FrameGrid& grid, std::size_t maxPairs,
                   std::vector<Pair>& out);

  /// One command, already encoded (whole beats): posts a receive of
  /// `replyWords`, sends, waits up to `timeout`, and returns the trailer of
  /// the reply left in `reply`, whatever its error code. On a timeout aborts
  /// (recovering where the abort is not enough) and throws ShellTimeout; on
  /// a reply that breaks the protocol recovers and throws ShellProtocolError.
  Trailer exchange(std::span<const std::uint32_t> packet, std::size_t replyWords, std::chrono::microseconds timeout,
                   std::vector<std::uint32_t>& reply);

  /// Halts and flushes the channels, resets the shell (CONTROL.SOFT_RESET),
  /// waits for READY and clears IRQ_STATUS. The shell's counters restart from 0.
  void recover();

  /// A command's timeout for `coreCycles` of work (ShellDriverConfig).
  std::chrono::microseconds timeoutFor(std::uint64_t coreCycles) const;

 private:
  void setUpInterrupts();
  /// Waits for the reply to the command just sent; false after `timeout`.
  bool awaitReply(std::chrono::microseconds timeout, std::vector<std::uint32_t>& reply);
  /// IRQ_STATUS read and written back (W1C): the interrupt acknowledged.
  void acknowledgeInterrupt();
  /// CONTROL.ABORT after a timeout, then the ABORTED reply; recovers when
  /// none comes or the input is left inside a packet. Returns whether the abort was enough.
  bool abortCommand(std::vector<std::uint32_t>& reply);
  /// Polls STATUS until no command is open (BUSY, IN_PACKET, REPLY_OPEN); false after abortTimeout.
  bool waitClosed();
  void waitReady();
  std::uint32_t status() { return transport_.readRegister(statusRegister()); }
  static std::uint32_t statusRegister();

  ShellTransport& transport_;
  ShellDriverConfig config_;
  ShellFormat format_;
  ShellDriverEvents events_;
  std::vector<std::uint32_t> packet_, reply_;  // reused from command to command
};

}  // namespace bpaccel
