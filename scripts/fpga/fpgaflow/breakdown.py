"""Where the core's ECP5 area goes: extra Yosys runs, synthesis only."""
from __future__ import annotations

import math

from .design import Design
from .ecp5 import Synthesis, comb_cells
from .tools import KEEP_REPLICAS, Runner, stat_cells

ROTATOR = "Rotator"


def breakdown(runner: Runner, yosys: str, design: Design, synthesis: Synthesis) -> dict:
    """The core's cells per part.

    * Rotator: the flat core (the real run minus the wrapper) minus the flat core
      synthesised with the Rotator black-boxed. The rotator is not synthesised on
      its own: alone, ABC9's depth-driven mapping duplicates its log2(m) mux stages
      into per-output m:1 muxes (O(m^2): 108k LUT4 at m = 32), which the flat design
      does not do.
    * Every other module (a "part": Loader, RunControl, AddressSequencer, the engine, the
      result queue, ...): synthesised as top with the parts it instantiates (and the
      Rotator) black-boxed, so each cell is counted in exactly one part; the engine's
      row is its own glue (A registers, pipeline), not its sub-parts.
    * Top level + buffers: the rest (flat core minus all of the above); it
      also absorbs what flattening saves across module boundaries (registers that
      are equal in two modules are merged in the flat design), so it is a residual.
    Memory-holding modules (CoordBuffer, the stream engine) stay flattened into the top,
    as in the real run."""
    top, memory = design.top, design.memory_module
    mem_modules = {memory} | {r["module"] for r in synthesis.registered}
    holds_mem = {n for n in design.modules if any(design.instantiates(n, mm) for mm in mem_modules)}
    subs = [n for n in design.modules if n not in (top, ROTATOR) and n not in mem_modules and n not in holds_mem]
    has_rot = ROTATOR in design.modules
    parts = set(subs) | ({ROTATOR} if has_rot else set())
    script = [f"read_verilog -sv {' '.join(synthesis.files)}", KEEP_REPLICAS.strip(), "design -save sources"]
    for sub in subs:
        inner = sorted(c for c in parts if c != sub and design.instantiates(sub, c))
        script += [f"hierarchy -top {sub}"] + ([f"blackbox {' '.join(inner)}"] if inner else []) + \
                  [f"synth_ecp5 -top {sub}", f"tee -q -o breakdown_{sub}.json stat -json", "design -load sources"]
    script += [f"hierarchy -top {top}"] + ([f"blackbox {ROTATOR}"] if has_rot else []) + \
              [f"synth_ecp5 -top {top}", "tee -q -o breakdown_norot.json stat -json"]
    runner.yosys("yosys breakdown", yosys, "breakdown", "\n".join(script) + "\n", "per-part synthesis")

    def row(cells: dict[str, int]) -> dict:
        # Black-boxed sub-parts appear as cells named after their module: counted in their own row.
        cells = {k: v for k, v in cells.items() if k not in parts and k != "$scopeinfo"}
        return {"lut4_slots": comb_cells(cells), "ffs": cells.get("TRELLIS_FF", 0),
                "dp16kd": cells.get("DP16KD", 0), "ccu2c": cells.get("CCU2C", 0), "cells": cells}

    core = row(synthesis.core_cells())
    norot = row(stat_cells(runner.work / "breakdown_norot.json")[0])
    out = {}
    rest = {k: core[k] for k in ("lut4_slots", "ffs", "dp16kd", "ccu2c")}
    if has_rot:
        # The rotator is combinational: its registers are in the top level. (With it
        # black-boxed, Yosys no longer packs the B-side memory output registers into the
        # DP16KD, so an FF difference would be meaningless.)
        out[ROTATOR] = {"lut4_slots": core["lut4_slots"] - norot["lut4_slots"], "ffs": 0, "dp16kd": 0,
                        "ccu2c": core["ccu2c"] - norot["ccu2c"]}
        for k in rest:
            rest[k] -= out[ROTATOR][k]
    for sub in subs:
        r = row(stat_cells(runner.work / f"breakdown_{sub}.json")[0])
        out[sub] = r
        for k in rest:
            rest[k] -= r[k]
    out[f"top level + {', '.join(sorted(holds_mem))} (residual)"] = rest
    m = design.m
    stages = math.ceil(math.log2(m)) if m > 1 else 0
    return {"what": "post-synthesis (not placed) ECP5 cells per part of the bare core (no wrapper); "
                    "lut4_slots = LUT4 + 2*CCU2C; see scripts/fpga/fpgaflow/breakdown.py for the method",
            "flat_core_synth": {k: core[k] for k in ("lut4_slots", "ffs", "dp16kd", "ccu2c")},
            "expected": {"rotator_2to1_muxes": 192 * m * stages, "rotator_stages": stages,
                         "comparators_32bit": 6 * m, "memories": 6 * m},
            "modules": out}
