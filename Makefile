# Broad-phase collision-detection accelerator: generator, tests, Verilog.
# Every target depends on `deps`, so a fresh clone needs no other step.

SHELL := /bin/bash
SBT   := ./scripts/sbt

# Debian's interpreter, which has python3-matplotlib.
PYTHON := /usr/bin/python3

# Configuration of `make verilog` (see README): architecture (stream: one
# memory read a cycle, the default: faster and half the LUTs of the seed at
# m = 8 (docs/fpga.md), and it scales; seed: the published design, see
# docs/microarchitecture.md), parallelism, objects per run (empty: the
# architecture's default, which the generator knows), key width. The
# generator's defaults are these (AccelParamsSpec checks it).
ARCH      ?= stream
M         ?= 8
CAPACITY  ?=
KEY_WIDTH ?= 32
# How `make verilog` builds the coordinate memories (docs/fpga.md): inferred
# (SyncReadMem, the default) or ecp5-outreg (the first output register inside
# the DP16KD; same cycles). `make fpga` builds FPGA_MEMORY_STYLE, by default
# inferred too: ecp5-outreg was not measured faster at m = 8 (docs/fpga.md).
MEMORY_STYLE ?=
FPGA_MEMORY_STYLE ?=
# The ECP5 part `make fpga` places on (scripts/fpga/fpgaflow/ecp5.py PARTS):
# lfe5u-85f (speed 6) or lfe5um5g-85f (speed 8); empty: the flow's default,
# lfe5u-85f. Another part names the report with a suffix.
FPGA_PART ?=
EMIT_ARGS = --arch $(ARCH) --m $(M) --key-width $(KEY_WIDTH) $(if $(CAPACITY),--capacity $(CAPACITY))
# Folder and report names come from one rule (scripts/fpga/fpgaflow/names.py).
NAMES = $(PYTHON) scripts/fpga/names.py --arch $(ARCH) --m $(M) --key-width $(KEY_WIDTH) $(if $(CAPACITY),--capacity $(CAPACITY))
DESIGN_NAME := $(shell $(NAMES))
KEY_SUFFIX  := $(shell $(NAMES) --key-suffix)
FPGA_DESIGN := $(shell $(NAMES) $(if $(FPGA_MEMORY_STYLE),--memory-style $(FPGA_MEMORY_STYLE)))
FPGA_NAME   := $(shell $(NAMES) $(if $(FPGA_MEMORY_STYLE),--memory-style $(FPGA_MEMORY_STYLE)) $(if $(FPGA_PART),--part $(FPGA_PART)))
VERILOG_DIR ?= generated/$(shell $(NAMES) $(if $(MEMORY_STYLE),--memory-style $(MEMORY_STYLE)))

# The host is built for one configuration: ARCH, M, CAPACITY and KEY_WIDTH
# above (a device with narrower keys gets each cell's keys narrowed and the
# host checks its pairs with the full keys; docs/host.md). It verilates the
# AXI shell around that core (docs/integration.md): the shell's Verilog,
# bpaccel_params.h and bpaccel_shell.h come from one emission. Its streams
# carry a box a beat or more (256 bits for keys above 16 bits, 128 below),
# so the core takes a box a cycle and its cycles are the model's.
HOST_STREAM_BITS ?= $(shell [ $(KEY_WIDTH) -le 16 ] && echo 128 || echo 256)
HOST_DUAL_CLOCK  ?= true
HOST_VERILOG := build/host-shell/$(DESIGN_NAME)-w$(HOST_STREAM_BITS)$(if $(filter true,$(HOST_DUAL_CLOCK)),,-1clk)
HOST_BUILD   := build/host-$(DESIGN_NAME)
# Where the bpaccel CLI goes; the benchmark's configuration gets its own.
# A device of narrower keys gets its own too (build/bin-k16).
HOST_BIN_DIR ?= build/bin$(KEY_SUFFIX)
SCALA_SOURCES := $(wildcard src/bpaccel/*.scala) build.sbt
# Non-empty when one of the files $(1) is missing or older than a Scala source.
stale = $(strip $(foreach f,$(1),$(if $(wildcard $(f)),$(shell find $(SCALA_SOURCES) -newer $(f) | head -1),missing)))
# Extra options for `bpaccel-bench run` (see `build/bin/bpaccel-bench run --help`).
BENCH_ARGS ?=

# The FPGA flow's own test runs on this configuration.
FPGA_TEST_VERILOG := build/fpga-verilog/test-m2
FPGA_TEST_STREAM_VERILOG := build/fpga-verilog/test-stream-m2

.PHONY: all deps test test-hw test-host test-fpga host host-check bench verilog fpga fpga-sweep clean \
        host-sanitize test-sanitize print-other-arch fuzz test-fuzz fuzz-long formal-long

all: test

deps:
	@./scripts/deps.sh

# Every test of the project, part by part; the last line gives each part's
# time against the 10-minute budget (scripts/test_parts.sh). The fuzz targets
# are built at low priority from the start, in the cores the parts leave idle.
test: deps
	@MAKE="$(MAKE)" scripts/test_parts.sh --ahead fuzz sbt=test-hw host=test-host fpga=test-fpga fuzz=test-fuzz

# The Chisel generator: golden model, ChiselTest (Scala simulator and Verilator),
# Verilog lint and memory structure. The same sbt session then emits the
# Verilog the host and the FPGA flow's test build, where it is out of date,
# which spares each an sbt start-up, and in one forked JVM (EmitAll), which
# spares each a JVM's.
test-hw: deps
	$(SBT) test $(call emit,$(if $(call stale,$(HOST_VERILOG)/filelist.f),$(EMIT_HOST) +) \
	  $(if $(call stale,$(BINNING_PARAMS_DIR)/bpaccel_binning_params.h),$(EMIT_BINNING_PARAMS) +) \
	  $(if $(call stale,$(HOST_FRAME_SHELL)/filelist.f),$(EMIT_HOST_FRAME_SHELL) +) \
	  $(if $(call stale,$(FPGA_TEST_VERILOG)/filelist.f $(FPGA_TEST_STREAM_VERILOG)/filelist.f),$(EMIT_FPGA_TEST)))

# The sbt command that runs emitters ("EmitShell <options> + EmitBinning
# <options> ...") in one forked JVM (bpaccel.EmitAll); nothing for none.
emit = $(if $(strip $(1)),"runMain bpaccel.EmitAll $(strip $(1))")

# The formal checks at depths that cover a whole run of each small
# configuration (docs/verification.md); `make test` runs shallower ones.
formal-long: deps
	BPACCEL_FORMAL_LONG=1 $(SBT) "testOnly bpaccel.FormalSpec bpaccel.FormalMutantSpec bpaccel.binning.BinningFormalSpec"

# The C++ host (build/bin/bpaccel, build/bin/bpaccel-bench) with the Verilated shell and core, and its tests.
EMIT_HOST = EmitShell $(EMIT_ARGS) --stream-bits $(HOST_STREAM_BITS) --dual-clock $(HOST_DUAL_CLOCK) --target-dir $(HOST_VERILOG)
$(HOST_VERILOG)/filelist.f: $(SCALA_SOURCES) $(wildcard src/bpaccel/shell/*.scala) | deps
	$(SBT) $(call emit,$(EMIT_HOST))

# The binning device's C header and JSON parameters (EmitBinning --params-only), for the host's model of it.
BINNING_PARAMS_DIR := build/host-binning
EMIT_BINNING_PARAMS = EmitBinning --params-only --target-dir $(BINNING_PARAMS_DIR)
$(BINNING_PARAMS_DIR)/bpaccel_binning_params.h: $(SCALA_SOURCES) $(wildcard src/bpaccel/binning/*.scala) | deps
	$(SBT) $(call emit,$(EMIT_BINNING_PARAMS))

# A small binning shell, verilated for the tests of the driver's FRAME path
# against the hardware (host/src/device/rtl/frame): 8 lane groups of 2
# lanes, 512 boxes a frame, 128-bit streams, two clocks.
HOST_FRAME_SHELL := build/host-shell/binning-g8-c512-w128
HOST_FRAME_SHELL_ARGS := --group-bits 1,1,1 --lanes-per-group 2 --cell-bits 4 --capacity 512 --group-capacity 256 \
  --intake-boxes 4 --pairs-per-beat 4 --stream-bits 128 --dual-clock true
EMIT_HOST_FRAME_SHELL = EmitShell --arch binning $(HOST_FRAME_SHELL_ARGS) --target-dir $(HOST_FRAME_SHELL)
$(HOST_FRAME_SHELL)/filelist.f: $(SCALA_SOURCES) $(wildcard src/bpaccel/shell/*.scala src/bpaccel/binning/*.scala) | deps
	$(SBT) $(call emit,$(EMIT_HOST_FRAME_SHELL))
HOST_GENERATED := $(HOST_VERILOG)/filelist.f $(BINNING_PARAMS_DIR)/bpaccel_binning_params.h $(HOST_FRAME_SHELL)/filelist.f
HOST_GENERATED_DIRS := -DBPACCEL_VERILOG_DIR=$(abspath $(HOST_VERILOG)) -DBPACCEL_BINNING_DIR=$(abspath $(BINNING_PARAMS_DIR)) \
  -DBPACCEL_FRAME_SHELL_DIR=$(abspath $(HOST_FRAME_SHELL))

# Configures and builds the host in folder $(1) with cmake options $(2), its programs going to $(3).
build_host = cmake -S host -B $(1) -G Ninja $(2) $(HOST_GENERATED_DIRS) -DBPACCEL_BIN_DIR=$(abspath $(3)) && \
  cmake --build $(1) -j 2

host: deps $(HOST_GENERATED)
	$(call build_host,$(HOST_BUILD),,$(HOST_BIN_DIR))

# The host's tests run on a build of their own, all of it at -O1
# (host/cmake/check.cmake): it times nothing, and builds in 318 CPU-s where
# -O3 took 369; `make host` and the benchmark stay at -O3.
HOST_CHECK_BUILD := build/host-check-$(DESIGN_NAME)
host-check: deps $(HOST_GENERATED)
	$(call build_host,$(HOST_CHECK_BUILD),-C host/cmake/check.cmake,$(HOST_CHECK_BUILD)/bin)

test-host: host-check
	ctest --test-dir $(HOST_CHECK_BUILD) --output-on-failure -j 2

# The seed's results table: Bullet's broad phases against the accelerator on
# the bouncing cube, with results/bench.json, plots and a picture of the scene.
# It runs a device measured on the FPGA (docs/fpga.md; m = 64 routes at
# 83.82 MHz at 6b635ea, placer seed 3, which costs the bench's scene less device time
# than m = 32 at 93.4, measured before bipartite runs): the host is built
# for BENCH_ARCH and BENCH_M, whose report in
# results/fpga gives the clock. The other targets keep ARCH and M.
BENCH_ARCH ?= stream
BENCH_M    ?= 64
BENCH_BIN_DIR := build/bench-bin
bench: deps
	$(MAKE) bench-run ARCH=$(BENCH_ARCH) M=$(BENCH_M) HOST_BIN_DIR=$(BENCH_BIN_DIR)

bench-run: host
	mkdir -p results; set -o pipefail; $(HOST_BIN_DIR)/bpaccel-bench run --json results/bench.json $(BENCH_ARGS) | tee results/bench.txt
	$(PYTHON) scripts/plot_bench.py --json results/bench.json --out-dir results
	$(HOST_BIN_DIR)/bpaccel-bench scene --objects 100 --frames 30 --out results/scene.json
	$(PYTHON) scripts/render_scene.py --json results/scene.json --out results/scene.png
	$(MAKE) bench-families-run BENCH_FAMILIES_OBJECTS=8000 BENCH_FAMILIES_DIR=results/families

# The scene families unlike the bench's cube (docs/results.md, "Scene
# families"): size variance, clusters, a flat world, long thin boxes, a layer
# at one height. The software only (the cpu backend's rows against Bullet and
# the peers; the fixed grid rows at the sizes the automatic choice moves
# between), every frame validated. `make bench` runs each at 8000 objects
# into results/families; this target at 1000, 8000 and 100,000 into
# results/families-all.
BENCH_FAMILIES         ?= sizes clusters flat poles layer
BENCH_FAMILIES_OBJECTS ?= 1000 8000 100000
BENCH_FAMILIES_DIR     ?= results/families-all
BENCH_FAMILIES_ARGS    ?= --frames 10 --warmup 2 --no-accelerator --grid-cell-sizes 16 32 64 128 256 --whole-step-objects 0 --many-worlds 0 --query-objects none
.PHONY: bench-families bench-families-run
bench-families: deps
	$(MAKE) bench-families-run ARCH=$(BENCH_ARCH) M=$(BENCH_M) HOST_BIN_DIR=$(BENCH_BIN_DIR)

bench-families-run: host
	mkdir -p $(BENCH_FAMILIES_DIR); set -o pipefail; $(HOST_BIN_DIR)/bpaccel-bench run --families $(BENCH_FAMILIES) \
	  --objects $(BENCH_FAMILIES_OBJECTS) $(BENCH_FAMILIES_ARGS) --json $(BENCH_FAMILIES_DIR)/bench.json | tee $(BENCH_FAMILIES_DIR)/bench.txt

# The seed's sizes, 100,000 and 1,000,000 objects: device cycles from the
# cycle-exact model backend (the Verilated one would take hours), every frame
# of every method still validated, a few frames a row. Methods whose set-up or
# sweep cannot be stopped midway are skipped with their reason where they would
# take many minutes (docs/results.md); --max-method-seconds stops the others.
BENCH_LARGE_ARGS ?= --objects 100000 1000000 --backend model --frames 3 --warmup 1 --whole-step-objects 0 --many-worlds 0
.PHONY: bench-large bench-run bench-large-run
bench-large: deps
	$(MAKE) bench-large-run ARCH=$(BENCH_ARCH) M=$(BENCH_M) HOST_BIN_DIR=$(BENCH_BIN_DIR)

bench-large-run: host
	mkdir -p results/large; set -o pipefail; $(HOST_BIN_DIR)/bpaccel-bench run --json results/large/bench.json $(BENCH_LARGE_ARGS) | tee results/large/bench.txt
	$(PYTHON) scripts/plot_bench.py --json results/large/bench.json --out-dir results/large

# The same host, Verilated model and tests under AddressSanitizer and
# UndefinedBehaviorSanitizer (host/cmake/sanitize.cmake); any report fails.
HOST_SANITIZE_BUILD := build/host-asan-$(DESIGN_NAME)
SANITIZER_ENV := ASAN_OPTIONS=detect_leaks=1:detect_stack_use_after_return=1:strict_init_order=1 \
                 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
host-sanitize: deps $(HOST_GENERATED)
	$(call build_host,$(HOST_SANITIZE_BUILD),-C host/cmake/sanitize.cmake,$(HOST_SANITIZE_BUILD)/bin)

# CI runs it after `make test` (.ci/run): its build and run take about as long
# as the rest of the host's tests together. The packaging test is left to
# test-host: it builds an outside project with plain flags, which cannot link
# sanitized libraries.
test-sanitize: host-sanitize
	$(SANITIZER_ENV) ctest --test-dir $(HOST_SANITIZE_BUILD) --output-on-failure -j 2 -E '^installed_package_example$$'

# The architecture that is not the default (CI sanitizes the host built for it).
print-other-arch:
	@echo $(if $(filter seed,$(ARCH)),stream,seed)

# libFuzzer targets on the box-file parsers and the pair-finding API
# (host/fuzz/README.md), built with clang, ASan and UBSan; no Verilator needed.
FUZZ_BUILD   := build/fuzz
# make test replays each target's committed corpus and searches on for
# FUZZ_SECONDS (20 s: about 24,000 pairs inputs), the two file parsers
# (box file, Broadmark's .aabbs) for half of it each; fuzz-long is the deep search.
FUZZ_SECONDS ?= 20
FUZZ_RUNS    ?= 1000000
fuzz: deps
	cmake -S host/fuzz -B $(FUZZ_BUILD) -G Ninja -DCMAKE_CXX_COMPILER=clang++
	cmake --build $(FUZZ_BUILD) -j 2

# A short run of each target (FUZZ_SECONDS each), part of `make test`.
test-fuzz: fuzz
	host/fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS)

# The long run: FUZZ_RUNS executions of each target, side by side.
fuzz-long: fuzz
	nice host/fuzz/run.sh --runs $(FUZZ_BUILD) $(FUZZ_RUNS)

# FPGA flow (docs/fpga.md): ECP5 synthesis, place and route on FPGA_PART with
# a measured Fmax, and a Xilinx 7-series synthesis estimate. The Verilog does
# not depend on the part: its folder is named by the design alone.
# ARCH=binning: the binning device (docs/binning.md) as EmitBinning builds it,
# its defaults or BINNING_ARGS (EmitBinning's own options, e.g.
# BINNING_ARGS="--lanes-per-group 4"); M, CAPACITY and KEY_WIDTH do not apply.
# Its folder and report are named from the parameter file it writes.
BINNING_ARGS ?=
BINNING_STAGING := build/fpga-verilog/binning-emitting
fpga: deps
ifeq ($(ARCH),binning)
	rm -rf $(BINNING_STAGING)
	$(SBT) "runMain bpaccel.binning.EmitBinning $(BINNING_ARGS) --target-dir $(BINNING_STAGING)"
	name=$$($(PYTHON) scripts/fpga/names.py --params $(BINNING_STAGING)/bpaccel_params.json) && \
	  rm -rf build/fpga-verilog/$$name && mv $(BINNING_STAGING) build/fpga-verilog/$$name && \
	  $(PYTHON) scripts/fpga/flow.py --verilog-dir build/fpga-verilog/$$name $(if $(FPGA_PART),--part $(FPGA_PART)) $(FPGA_ARGS)
else
	$(MAKE) verilog ARCH=$(ARCH) M=$(M) CAPACITY=$(CAPACITY) KEY_WIDTH=$(KEY_WIDTH) MEMORY_STYLE=$(FPGA_MEMORY_STYLE) VERILOG_DIR=build/fpga-verilog/$(FPGA_DESIGN)
	$(PYTHON) scripts/fpga/flow.py --verilog-dir build/fpga-verilog/$(FPGA_DESIGN) --out results/fpga/$(FPGA_NAME).json $(if $(FPGA_PART),--part $(FPGA_PART)) $(FPGA_ARGS)
endif

fpga-sweep: deps
	$(PYTHON) scripts/fpga/sweep.py --arch $(ARCH) --key-width $(KEY_WIDTH) $(if $(CAPACITY),--capacity $(CAPACITY)) $(if $(FPGA_MEMORY_STYLE),--memory-style $(FPGA_MEMORY_STYLE)) --verilog-root build/fpga-verilog --emit always --budget-min 60

# Both architectures at m = 2 (the stream with a small memory, so the flow stays quick), emitted by one sbt run.
EMIT_FPGA_TEST = EmitVerilog --arch seed --m 2 --target-dir $(FPGA_TEST_VERILOG) + \
                 EmitVerilog --arch stream --m 2 --capacity 512 --target-dir $(FPGA_TEST_STREAM_VERILOG)
$(FPGA_TEST_VERILOG)/filelist.f $(FPGA_TEST_STREAM_VERILOG)/filelist.f &: $(SCALA_SOURCES) | deps
	$(SBT) $(call emit,$(EMIT_FPGA_TEST))
# Options for flow.py, e.g. FPGA_ARGS="--router router2 --threads 2".
FPGA_ARGS ?=

# The flow end to end on both architectures at m = 2.
test-fpga: deps $(FPGA_TEST_VERILOG)/filelist.f $(FPGA_TEST_STREAM_VERILOG)/filelist.f
	$(PYTHON) scripts/fpga/test_flow.py $(FPGA_TEST_VERILOG) $(FPGA_TEST_STREAM_VERILOG)

# SystemVerilog (one file per module, filelist.f), bpaccel_params.h and
# bpaccel_params.json for one configuration.
verilog: deps
	$(SBT) "runMain bpaccel.EmitVerilog $(EMIT_ARGS) $(if $(MEMORY_STYLE),--memory-style $(MEMORY_STYLE)) --target-dir $(VERILOG_DIR)"
	cd $(VERILOG_DIR) && verilator --lint-only -Wall lint_waivers.vlt -F filelist.f --top-module BroadPhaseAccel
	@echo "Verilog for arch=$(ARCH), m=$(M), capacity $(if $(CAPACITY),$(CAPACITY),by default): $(VERILOG_DIR)/filelist.f"

clean:
	rm -rf target project/target generated build test_run_dir

# The AXI shell's targets (shell-verilog, shell-registers, test-shell, shell-fusesoc, shell-synth).
include mk/shell.mk
