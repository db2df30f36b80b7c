#include "shell_probe.hpp"

#include <fmt/format.h>

#include "bpaccel_shell.h"
#include "shell_reply.hpp"

namespace bpaccel {
namespace {

// A field of a register's value, by its generated mask and shift.
constexpr std::uint32_t field(std::uint32_t value, std::uint32_t mask, unsigned shift) { return (value & mask) >> shift; }

[[noreturn]] void differs(const ShellIdentity& expected, const char* what, std::uint32_t device, std::uint32_t built) {
  throw ShellProbeError(fmt::format("shell: the device's {} is {:#x} but this host was built for {:#x} ({}: "
                                    "{}); rebuild the host for this bitstream, or load the one it was built for",
                                    what, device, built, "bpaccel_shell.h", expected.fingerprintText));
}

}  // namespace

// ID, VERSION and FINGERPRINT sit at the same offsets in every shell's register map.
void probeShell(ShellTransport& transport, const ShellIdentity& expected) {
  const std::uint32_t id = transport.readRegister(BPACCEL_SHELL_REG_ID);
  if (id != BPACCEL_SHELL_REG_ID_RESET)
    throw ShellProbeError(fmt::format("shell: no bpaccel shell answers: ID reads {:#010x}, not {:#010x} (\"BPAC\")", id,
                                      BPACCEL_SHELL_REG_ID_RESET));
  const std::uint32_t version = transport.readRegister(BPACCEL_SHELL_REG_VERSION);
  if (field(version, BPACCEL_SHELL_REG_VERSION_PROTOCOL_MASK, BPACCEL_SHELL_REG_VERSION_PROTOCOL_SHIFT) !=
      field(expected.version, BPACCEL_SHELL_REG_VERSION_PROTOCOL_MASK, BPACCEL_SHELL_REG_VERSION_PROTOCOL_SHIFT))
    differs(expected, "VERSION.PROTOCOL", version, expected.version);
  if (field(version, BPACCEL_SHELL_REG_VERSION_REGISTER_MAP_MASK, BPACCEL_SHELL_REG_VERSION_REGISTER_MAP_SHIFT) !=
      field(expected.version, BPACCEL_SHELL_REG_VERSION_REGISTER_MAP_MASK,
            BPACCEL_SHELL_REG_VERSION_REGISTER_MAP_SHIFT))
    differs(expected, "VERSION.REGISTER_MAP", version, expected.version);
  for (const ExpectedRegister& r : expected.capabilities) {
    const std::uint32_t value = transport.readRegister(r.offset);
    if (value != r.value) differs(expected, r.name, value, r.value);
  }
  const std::uint32_t fingerprint = transport.readRegister(BPACCEL_SHELL_REG_FINGERPRINT);
  if (fingerprint != expected.fingerprint)
    throw ShellProbeError(fmt::format("shell: the device's FINGERPRINT is {:#010x} but this host was built for "
                                      "{:#010x} ({}); every capability register agrees, so the bitstream differs "
                                      "in an option they do not show (FIFO depth, result queue, memory stages or style)",
                                      fingerprint, expected.fingerprint, expected.fingerprintText));
}

}  // namespace bpaccel
