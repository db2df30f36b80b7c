#pragma once
// The probe of a shell (docs/integration.md, "Probe"): is the device at a
// transport the shell whose headers this program was built with?

#include <cstdint>
#include <string>
#include <vector>

#include "shell_format.hpp"
#include "shell_transport.hpp"

namespace bpaccel {

/// The shell this program was built for: bpaccel_shell.h and bpaccel_params.h read into a ShellFormat.
ShellFormat builtShellFormat();

/// A register the probe compares, with the value bpaccel_shell.h gives it.
struct ExpectedRegister {
  const char* name;
  std::uint32_t offset;
  std::uint32_t value;
};

/// The capability registers (ARCH, OPCODES, LANES, ...), with the built shell's values.
const std::vector<ExpectedRegister>& builtCapabilities();

/// Reads ID, VERSION, every capability register and FINGERPRINT and throws
/// ShellProbeError at the first that differs from the built shell's,
/// naming it, both values and the configuration the host was built for.
void probeShell(ShellTransport& transport);

}  // namespace bpaccel
