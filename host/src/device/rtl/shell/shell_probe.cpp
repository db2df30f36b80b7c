#include "shell_probe.hpp"

#include <fmt/format.h>

#include "bpaccel_params.h"
#include "bpaccel_shell.h"
#include "shell_reply.hpp"

namespace bpaccel {
namespace {

// A field of a register's value, by its generated mask and shift.
constexpr std::uint32_t field(std::uint32_t value, std::uint32_t mask, unsigned shift) { return (value & mask) >> shift; }

#define BPACCEL_CAPABILITY(name) ExpectedRegister{#name, BPACCEL_SHELL_REG_##name, BPACCEL_SHELL_REG_##name##_RESET}

[[noreturn]] void differs(const char* what, std::uint32_t device, std::uint32_t built) {
  throw ShellProbeError(fmt::format("shell: the device's {} is {:#x} but this host was built for {:#x} ({}: "
                                    "{}); rebuild the host for this bitstream, or load the one it was built for",
                                    what, device, built, "bpaccel_shell.h", BPACCEL_SHELL_FINGERPRINT_TEXT));
}

}  // namespace

ShellFormat builtShellFormat() {
  ShellFormat f;
  f.wordsPerBeat = BPACCEL_SHELL_WORDS_PER_BEAT;
  f.boxWords = BPACCEL_SHELL_BOX_WORDS;
  f.indexWords = BPACCEL_SHELL_INDEX_WORDS;
  f.lanes = BPACCEL_M;
  f.indexWidth = BPACCEL_INDEX_WIDTH;
  f.keyWidth = BPACCEL_KEY_WIDTH;
  f.capacity = BPACCEL_CAPACITY;
  f.bipartite = BPACCEL_BIPARTITE_RUNS != 0;
  f.cellBits = BPACCEL_SHELL_REG_CELL_BITS_RESET;
  f.check();
  return f;
}

const std::vector<ExpectedRegister>& builtCapabilities() {
  static const std::vector<ExpectedRegister> registers = {
      BPACCEL_CAPABILITY(ARCH),          BPACCEL_CAPABILITY(OPCODES),       BPACCEL_CAPABILITY(LANES),
      BPACCEL_CAPABILITY(CAPACITY),      BPACCEL_CAPABILITY(KEY_WIDTH),     BPACCEL_CAPABILITY(INDEX_WIDTH),
      BPACCEL_CAPABILITY(STREAM_BITS),   BPACCEL_CAPABILITY(BATCH_CELLS),   BPACCEL_CAPABILITY(FEATURES),
      BPACCEL_CAPABILITY(RUN_OVERHEAD_CYCLES), BPACCEL_CAPABILITY(READ_LATENCY), BPACCEL_CAPABILITY(FORMAT),
      BPACCEL_CAPABILITY(LANE_GROUPS),   BPACCEL_CAPABILITY(LANES_PER_GROUP), BPACCEL_CAPABILITY(CELL_BITS),
      BPACCEL_CAPABILITY(INTAKE_BOXES),
  };
  return registers;
}

void probeShell(ShellTransport& transport) {
  const std::uint32_t id = transport.readRegister(BPACCEL_SHELL_REG_ID);
  if (id != BPACCEL_SHELL_REG_ID_RESET)
    throw ShellProbeError(fmt::format("shell: no bpaccel shell answers: ID reads {:#010x}, not {:#010x} (\"BPAC\")", id,
                                      BPACCEL_SHELL_REG_ID_RESET));
  const std::uint32_t version = transport.readRegister(BPACCEL_SHELL_REG_VERSION);
  const std::uint32_t built = BPACCEL_SHELL_REG_VERSION_RESET;
  if (field(version, BPACCEL_SHELL_REG_VERSION_PROTOCOL_MASK, BPACCEL_SHELL_REG_VERSION_PROTOCOL_SHIFT) !=
      field(built, BPACCEL_SHELL_REG_VERSION_PROTOCOL_MASK, BPACCEL_SHELL_REG_VERSION_PROTOCOL_SHIFT))
    differs("VERSION.PROTOCOL", version, built);
  if (field(version, BPACCEL_SHELL_REG_VERSION_REGISTER_MAP_MASK, BPACCEL_SHELL_REG_VERSION_REGISTER_MAP_SHIFT) !=
      field(built, BPACCEL_SHELL_REG_VERSION_REGISTER_MAP_MASK, BPACCEL_SHELL_REG_VERSION_REGISTER_MAP_SHIFT))
    differs("VERSION.REGISTER_MAP", version, built);
  for (const ExpectedRegister& r : builtCapabilities()) {
    const std::uint32_t value = transport.readRegister(r.offset);
    if (value != r.value) differs(r.name, value, r.value);
  }
  const std::uint32_t fingerprint = transport.readRegister(BPACCEL_SHELL_REG_FINGERPRINT);
  if (fingerprint != BPACCEL_SHELL_FINGERPRINT)
    throw ShellProbeError(fmt::format("shell: the device's FINGERPRINT is {:#010x} but this host was built for "
                                      "{:#010x} ({}); every capability register agrees, so the bitstream differs "
                                      "in an option they do not show (FIFO depth, result queue, memory stages or style)",
                                      fingerprint, BPACCEL_SHELL_FINGERPRINT, BPACCEL_SHELL_FINGERPRINT_TEXT));
}

}  // namespace bpaccel
