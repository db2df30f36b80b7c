#pragma once
// The probe of a shell (docs/integration.md, "Probe"): is the device at a
// transport the shell a driver was built for?

#include "shell_identity.hpp"
#include "shell_transport.hpp"

namespace bpaccel {

/// Reads ID, VERSION, every capability register and FINGERPRINT and throws
/// ShellProbeError at the first that differs from `expected`, naming it,
/// both values and the configuration expected.
void probeShell(ShellTransport& transport, const ShellIdentity& expected);

}  // namespace bpaccel
