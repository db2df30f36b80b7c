"""Xilinx 7-series (estimate): Debian's Yosys synth_xilinx -family xc7;
post-synthesis cell counts only, no placement, no timing."""
from __future__ import annotations

import re
from pathlib import Path

from .design import Design
from .tools import EXIT_TOOL, KEEP_REPLICAS, FlowError, Runner, memory_mapping, stat_cells, tool_version
from .ecp5 import COORD_MEMORY_RE

FAMILY = "xc7"
PART_TEXT = f"7-series family (synth_xilinx -family {FAMILY}), no specific device"
LUTS = ["LUT1", "LUT2", "LUT3", "LUT4", "LUT5", "LUT6"]
FFS = ["FDRE", "FDSE", "FDCE", "FDPE", "LDCE", "LDPE"]
LUTRAM_RE = re.compile(r"^RAM(16|32|64|128|256|512)X\d+[SDMQ]?|^RAM(32|64)M(8|16)?$|^RAM32X16DR8$|^RAM64X8SW$")
SRL = ["SRL16E", "SRLC16E", "SRLC32E"]


def estimate(runner: Runner, debian_yosys: str, design: Design) -> dict:
    """synth_xilinx of the design as emitted (every memory inferred)."""
    if not Path(debian_yosys).exists():
        raise FlowError(EXIT_TOOL, f"{debian_yosys} not found (apt-get install yosys)")
    # -flatten: one netlist for the whole core, as the ECP5 run sees it (the memory modules
    # have one clock input and also map to block RAM on their own).
    text = runner.yosys("yosys synth_xilinx", debian_yosys, "xilinx",
                        f"read_verilog -sv {' '.join(design.files)}\n"
                        f"{KEEP_REPLICAS}"
                        f"synth_xilinx -flatten -family {FAMILY} -top {design.top}\n"
                        f"tee -q -o xilinx_stat.json stat -json\n", "Xilinx synthesis")
    cells, _ = stat_cells(runner.work / "xilinx_stat.json")
    memmap = memory_mapping(text, COORD_MEMORY_RE)
    return {
        "what": "estimate: Yosys synth_xilinx post-synthesis cell counts; no placement, no timing",
        "yosys_version": tool_version([debian_yosys, "-V"], runner.work),
        "luts": sum(cells.get(k, 0) for k in LUTS),
        "ffs": sum(cells.get(k, 0) for k in FFS),
        "bram_ramb18e1": cells.get("RAMB18E1", 0),
        "bram_ramb36e1": cells.get("RAMB36E1", 0),
        "bram36_equivalent": cells.get("RAMB36E1", 0) + cells.get("RAMB18E1", 0) / 2,
        "distributed_ram_cells": {k: v for k, v in cells.items() if LUTRAM_RE.match(k)},
        "srl_cells": {k: cells[k] for k in SRL if k in cells},
        "carry4": cells.get("CARRY4", 0),
        "dsp48e1": cells.get("DSP48E1", 0),
        "memory_mapping": memmap,
        "memories_in_bram": sum(v for k, v in memmap.items() if "BLOCKRAM" in k) == design.params["memory_count"],
        "cells": cells,
    }
