# The AXI shell (docs/integration.md): its Verilog, register page, FuseSoC core,
# tests and a quick synthesis. Included by the Makefile.
.PHONY: shell-verilog shell-registers test-shell shell-fusesoc shell-synth shell-measure

# The shell's configuration (EmitShell --help lists every option).
SHELL_ARCH     ?= stream
SHELL_M        ?= 8
SHELL_CAPACITY ?= 64
SHELL_STREAM_BITS ?= 128
SHELL_DUAL_CLOCK  ?= true
# SHELL_ARCH=binning: the binning core, its parameters in SHELL_BINNING (EmitShell's --group-bits,
# --lanes-per-group, --cell-bits, --capacity (boxes a frame), --group-capacity, --key-width,
# --intake-boxes, --pairs-per-beat; empty: BinningParams' defaults); SHELL_M and SHELL_CAPACITY are the CELLS cores'.
SHELL_BINNING  ?=
SHELL_TESTBENCH := test/fusesoc/bpaccel_shell_smoke_tb.sv
ifeq ($(SHELL_ARCH),binning)
SHELL_DIR      ?= build/shell/binning-w$(SHELL_STREAM_BITS)
SHELL_CORE_ARGS := $(SHELL_BINNING)
SHELL_CORE_TOP  := BinningCore
else
SHELL_DIR      ?= build/shell/$(SHELL_ARCH)-m$(SHELL_M)-w$(SHELL_STREAM_BITS)
# The FuseSoC smoke testbench sends CELLS commands.
SHELL_CORE_ARGS := --m $(SHELL_M) --capacity $(SHELL_CAPACITY) --smoke-testbench $(SHELL_TESTBENCH)
SHELL_CORE_TOP  := BroadPhaseAccel
endif
SHELL_VENV     := build/shell-venv/bin

# SystemVerilog, the core's C header and JSON parameters, bpaccel_shell.h, bpaccel_shell.rdl, registers.md,
# bpaccel_shell.core, and the registers as IP-XACT (bpaccel_shell_registers.xml, from the SystemRDL by PeakRDL).
shell-verilog: deps
	$(SBT) "runMain bpaccel.shell.EmitShell --arch $(SHELL_ARCH) $(SHELL_CORE_ARGS) --stream-bits $(SHELL_STREAM_BITS) --dual-clock $(SHELL_DUAL_CLOCK) --target-dir $(SHELL_DIR)"
	cd $(SHELL_DIR) && verilator --lint-only -Wall lint_waivers.vlt -F filelist.f --top-module BpaccelShell
	$(PYTHON) test/bpaccel/shell/comb_paths.py $(SHELL_DIR) BpaccelShell $(SHELL_CORE_TOP)
	cd $(SHELL_DIR) && $(abspath $(SHELL_VENV))/peakrdl ip-xact bpaccel_shell.rdl -o bpaccel_shell_registers.xml
	@echo "Shell for arch=$(SHELL_ARCH)$(if $(filter binning,$(SHELL_ARCH)),$(if $(SHELL_BINNING), $(SHELL_BINNING)),, m=$(SHELL_M)), $(SHELL_STREAM_BITS)-bit streams: $(SHELL_DIR)/filelist.f"

# docs/registers.md, from the default configuration's register map.
shell-registers: deps
	$(SBT) "runMain bpaccel.shell.EmitShell --capacity 64 --target-dir build/shell/registers"
	cp build/shell/registers/registers.md docs/registers.md

# The shell's own tests (also part of `make test` through test-hw): lint, no
# combinational port-to-port path, cocotb on Icarus, PeakRDL, FuseSoC.
test-shell: deps
	$(SBT) "testOnly bpaccel.shell.*"

# FuseSoC's lint and sim targets on one emitted configuration.
shell-fusesoc: shell-verilog
	mkdir -p $(SHELL_DIR)/fusesoc && cd $(SHELL_DIR)/fusesoc && \
	  $(abspath $(SHELL_VENV))/fusesoc --cores-root .. run --target lint bpaccel:accel:bpaccel_shell && \
	  $(abspath $(SHELL_VENV))/fusesoc --cores-root .. run --target sim bpaccel:accel:bpaccel_shell

# Yosys synthesis for the LFE5UM5G-85F (no place and route): cells of the shell alone and with its core.
shell-synth: shell-verilog
	cd $(SHELL_DIR) && yosys -q -l synth_ecp5.log -p "read_verilog -sv $$(grep '\.sv$$' filelist.f | tr '\n' ' '); synth_ecp5 -top BpaccelShell; tee -o synth_ecp5_stat.txt stat" && tail -40 synth_ecp5_stat.txt

# The cycles the shell adds to a bench-like batch (216 cells of about 54 boxes)
# at m = 64 with 256-bit streams on one clock (test/cocotb/measure_shell.py).
SHELL_MEASURE_DIR := build/shell/measure
shell-measure: deps
	$(SBT) "runMain bpaccel.shell.EmitShell --arch stream --m 64 --capacity 128 --stream-bits 256 --dual-clock false --target-dir $(SHELL_MEASURE_DIR)"
	BPACCEL_TEST_MODULE=measure_shell BPACCEL_MEASURE_OUT=$(abspath $(SHELL_MEASURE_DIR))/shell_measure.txt \
	  $(SHELL_VENV)/python test/cocotb/run.py $(SHELL_MEASURE_DIR)
