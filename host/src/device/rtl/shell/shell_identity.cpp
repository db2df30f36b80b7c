#include "shell_identity.hpp"

#include "bpaccel_params.h"
#include "shell_identity_of_header.hpp"

namespace bpaccel {

// The shell's registers and the core's header come from one emission.
static_assert(BPACCEL_SHELL_REG_LANES_RESET == BPACCEL_M && BPACCEL_SHELL_REG_CAPACITY_RESET == BPACCEL_CAPACITY &&
                  BPACCEL_SHELL_REG_KEY_WIDTH_RESET == BPACCEL_KEY_WIDTH &&
                  BPACCEL_SHELL_REG_INDEX_WIDTH_RESET == BPACCEL_INDEX_WIDTH &&
                  ((BPACCEL_SHELL_REG_FEATURES_RESET & BPACCEL_SHELL_REG_FEATURES_BIPARTITE_MASK) != 0) ==
                      (BPACCEL_BIPARTITE_RUNS != 0),
              "bpaccel_shell.h and bpaccel_params.h are of different emissions");

ShellIdentity builtShellIdentity() { return identityOfIncludedShellHeader(); }

}  // namespace bpaccel
