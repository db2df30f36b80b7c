#pragma once
// Who a shell is (docs/integration.md, "Probe"): its packets' layout, its
// capability registers, VERSION and FINGERPRINT, as one emission's
// bpaccel_shell.h gives them. The driver probes a device against one.

#include <cstdint>
#include <string>
#include <vector>

#include "shell_format.hpp"

namespace bpaccel {

/// A register the probe compares, with the value the shell's header gives it.
struct ExpectedRegister {
  const char* name;
  std::uint32_t offset;
  std::uint32_t value;
};

struct ShellIdentity {
  ShellFormat format;
  std::vector<ExpectedRegister> capabilities;  // ARCH, OPCODES, LANES, ...
  std::uint32_t version = 0;                   // VERSION: protocol and register map
  std::uint32_t fingerprint = 0;
  std::string fingerprintText;                 // the configuration, as the generator names it
};

/// The shell this program's driver was built for: the bpaccel_shell.h beside
/// its core (BPACCEL_VERILOG_DIR).
ShellIdentity builtShellIdentity();

}  // namespace bpaccel
