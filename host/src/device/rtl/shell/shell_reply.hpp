#pragma once
// A reply's trailer (docs/protocol.md, "Output packets") and the errors a
// driver reports.

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include "shell_format.hpp"

namespace bpaccel {

/// The trailer that ends every reply: the command's status and counters.
struct Trailer {
  std::uint32_t opcode = 0;
  std::uint32_t error = 0;    // 0: the command succeeded
  std::uint32_t detail = 0;   // the cell or box the error names
  std::uint32_t records = 0;  // records before the trailer
  std::uint32_t boxes = 0;    // boxes received
  std::uint32_t cells = 0;    // cells run (CELLS)
  std::uint64_t deviceCycles = 0;  // core cycles: intake plus runs
  std::uint64_t stallCycles = 0;   // lost waiting for room on the output
  std::uint64_t issueCycles = 0;   // the comparators had work
  std::uint64_t pairs = 0;         // overlapping pairs found
  std::uint64_t intakeCycles = 0;  // outside runs: loading no run hides, and the starts

  std::uint64_t runCycles() const { return deviceCycles - intakeCycles; }
};

/// The name of an error code as bpaccel_shell.h spells it ("ABORTED"), or "error <code>".
std::string shellErrorName(std::uint32_t code);

/// Every error of the shell driver.
class ShellError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The device answered with an error trailer; its records were discarded.
class ShellDeviceError : public ShellError {
 public:
  ShellDeviceError(const std::string& command, const Trailer& trailer);
  std::uint32_t code() const { return trailer_.error; }
  std::uint32_t detail() const { return trailer_.detail; }
  const Trailer& trailer() const { return trailer_; }

 private:
  Trailer trailer_;
};

/// A reply, or a register, that breaks the protocol: the device or the transport is not what the driver expects.
class ShellProtocolError : public ShellError {
 public:
  using ShellError::ShellError;
};

/// No reply came in time; the driver aborted the command (and recovered the device where the abort was not enough).
class ShellTimeout : public ShellError {
 public:
  using ShellError::ShellError;
};

/// The device at the transport is not the shell this host was built for (or none).
class ShellProbeError : public ShellError {
 public:
  using ShellError::ShellError;
};

/// The trailer at the end of `reply`. Throws ShellProtocolError when the reply
/// is not whole beats, is shorter than a trailer, or its trailer has no magic.
Trailer decodeTrailer(const ShellFormat& format, std::span<const std::uint32_t> reply);

/// The words of `reply` that hold its trailer's records, `recordWords` words
/// each, packed from the start. Throws ShellProtocolError when the words
/// before the trailer are not exactly the beats those records fill.
std::span<const std::uint32_t> recordWordsOf(const ShellFormat& format, std::span<const std::uint32_t> reply,
                                             const Trailer& trailer, unsigned recordWords);

}  // namespace bpaccel
