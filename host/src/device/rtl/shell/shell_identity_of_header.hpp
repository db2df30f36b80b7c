#pragma once
// The identity of the bpaccel_shell.h that the including file sees. A
// program may hold several shells' identities, one translation unit each,
// with that shell's emission first on its include path: hence a function
// of internal linkage, not a shared symbol.

#include "bpaccel_shell.h"
#include "shell_identity.hpp"

namespace bpaccel {
namespace {

#define BPACCEL_CAPABILITY(name) ExpectedRegister{#name, BPACCEL_SHELL_REG_##name, BPACCEL_SHELL_REG_##name##_RESET}

ShellIdentity identityOfIncludedShellHeader() {
  ShellIdentity id;
  ShellFormat& f = id.format;
  f.wordsPerBeat = BPACCEL_SHELL_WORDS_PER_BEAT;
  f.boxWords = BPACCEL_SHELL_BOX_WORDS;
  f.indexWords = BPACCEL_SHELL_INDEX_WORDS;
  f.lanes = BPACCEL_SHELL_REG_LANES_RESET;
  f.indexWidth = BPACCEL_SHELL_REG_INDEX_WIDTH_RESET;
  f.keyWidth = BPACCEL_SHELL_REG_KEY_WIDTH_RESET;
  f.capacity = BPACCEL_SHELL_REG_CAPACITY_RESET;
  f.bipartite = (BPACCEL_SHELL_REG_FEATURES_RESET & BPACCEL_SHELL_REG_FEATURES_BIPARTITE_MASK) != 0;
  f.cellBits = BPACCEL_SHELL_REG_CELL_BITS_RESET;
  f.check();
  id.capabilities = {
      BPACCEL_CAPABILITY(ARCH),          BPACCEL_CAPABILITY(OPCODES),       BPACCEL_CAPABILITY(LANES),
      BPACCEL_CAPABILITY(CAPACITY),      BPACCEL_CAPABILITY(KEY_WIDTH),     BPACCEL_CAPABILITY(INDEX_WIDTH),
      BPACCEL_CAPABILITY(STREAM_BITS),   BPACCEL_CAPABILITY(BATCH_CELLS),   BPACCEL_CAPABILITY(FEATURES),
      BPACCEL_CAPABILITY(RUN_OVERHEAD_CYCLES), BPACCEL_CAPABILITY(READ_LATENCY), BPACCEL_CAPABILITY(FORMAT),
      BPACCEL_CAPABILITY(LANE_GROUPS),   BPACCEL_CAPABILITY(LANES_PER_GROUP), BPACCEL_CAPABILITY(CELL_BITS),
      BPACCEL_CAPABILITY(INTAKE_BOXES),
  };
  id.version = BPACCEL_SHELL_REG_VERSION_RESET;
  id.fingerprint = BPACCEL_SHELL_FINGERPRINT;
  id.fingerprintText = BPACCEL_SHELL_FINGERPRINT_TEXT;
  return id;
}

#undef BPACCEL_CAPABILITY

}  // namespace
}  // namespace bpaccel
