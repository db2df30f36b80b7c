# Broad-phase collision-detection accelerator: generator, tests, Verilog.
# Every target depends on `deps`, so a fresh clone needs no other step.

SHELL := /bin/bash
SBT   := ./scripts/sbt

# Configuration of `make verilog` (see README): parallelism, objects per run, key width.
M         ?= 8
CAPACITY  ?= $(shell echo $$((256 * $(M))))
KEY_WIDTH ?= 32
VERILOG_DIR ?= generated/m$(M)

.PHONY: all deps test test-hw verilog lint clean

all: test

deps:
	@./scripts/deps.sh

# Every test of the project.
test: deps test-hw

# The Chisel generator: golden model, ChiselTest (Scala simulator and Verilator),
# Verilog lint and memory structure.
test-hw: deps
	$(SBT) test

# SystemVerilog (one file per module, filelist.f) and bpaccel_params.h for one configuration.
verilog: deps
	$(SBT) "runMain bpaccel.EmitVerilog --m $(M) --capacity $(CAPACITY) --key-width $(KEY_WIDTH) --target-dir $(VERILOG_DIR)"
	cd $(VERILOG_DIR) && verilator --lint-only -Wall -F filelist.f --top-module BroadPhaseAccel
	@echo "Verilog for m=$(M), capacity=$(CAPACITY): $(VERILOG_DIR)/filelist.f"

clean:
	rm -rf target project/target generated build test_run_dir
