// The transport of the shell this host was built for (BpaccelShell, verilated as VBpaccelShell).
#include "VBpaccelShell.h"
#include "bpaccel_shell.h"
#include "verilated_shell_transport_impl.hpp"

static_assert(bpaccel::verilated_shell::kWords<VBpaccelShell> == BPACCEL_SHELL_WORDS_PER_BEAT &&
                  bpaccel::verilated_shell::kDualClock<VBpaccelShell> == (BPACCEL_SHELL_DUAL_CLOCK != 0),
              "the Verilated shell's ports and bpaccel_shell.h are of different emissions");

template class bpaccel::VerilatedShellTransportOf<VBpaccelShell>;
