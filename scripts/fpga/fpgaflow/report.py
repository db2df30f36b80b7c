"""The flow's JSON report (results/fpga/<name>.json, schema bpaccel-fpga-1, read by
the bench and the docs) and its printed summary."""
from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import subprocess
from pathlib import Path

from . import ecp5, xilinx
from .design import Design
from .ecp5 import PlaceAndRoute, Synthesis, comb_cells
from .tools import REPO, log

GENERATOR_SOURCES = ["src", "build.sbt"]


def now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def source_revision() -> str | None:
    """The design a report measured: the last commit that changed the
    generator's sources (so commits of docs or scripts leave it alone),
    "-dirty" when the working tree's sources differ from it (make fpga emits
    the Verilog from that tree first); None outside a git checkout."""
    try:
        head = subprocess.run(["git", "log", "-1", "--format=%h", "--abbrev=7", "--", *GENERATOR_SOURCES],
                              cwd=REPO, capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", *GENERATOR_SOURCES], cwd=REPO,
                               capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    return (head + ("-dirty" if dirty else "")) or None


def header(design: Design, args, versions: dict, wrapper_info: dict, revision: str | None) -> dict:
    """What every report says first: the configuration, the tools and how they ran."""
    p = design.params
    return {
        "schema": "bpaccel-fpga-1",
        "arch": p["arch"],
        "memory_style": p["memory_style"],
        "m": p["m"],
        "capacity": p["capacity"],
        "key_width": p["key_width"],
        "date": now(),
        "source_revision": revision,
        "host": {"machine": platform.machine(), "cpus": os.cpu_count()},
        "verilog_dir": str(args.verilog_dir),
        "part": {"ecp5": ecp5.PARTS[args.part].text(), "ecp5_part": ecp5.PARTS[args.part].facts(),
                 "xilinx": xilinx.PART_TEXT},
        "clock_constraint_mhz": args.clock_mhz,
        "nextpnr_seed": args.seed,
        "nextpnr_router": args.router,
        "nextpnr_threads": args.threads,
        "nextpnr_placer": args.placer or "default",
        "tool_versions": versions,
        "wrapper": wrapper_info,
    }


def placed(pnr: PlaceAndRoute, synthesis: Synthesis, m: int, clock_mhz: float) -> dict:
    """The fitting design's measured ECP5 section."""
    clk_net, fmax = ecp5.clock(pnr.report)
    used = pnr.utilisation
    luts = used.get("TRELLIS_COMB", {}).get("used")
    ffs = used.get("TRELLIS_FF", {}).get("used")
    wrapper = synthesis.wrapper_cells
    return {
        "status": "ok",
        "fits": True,
        "result_valid": True,
        "ecp5": {
            "what": "measured: nextpnr-ecp5 place and route of the wrapper FpgaTop around the core",
            "luts": luts,
            "luts_note": "LUT4 slots used after packing (TRELLIS_COMB: plain LUT4s plus the two LUT halves of each CCU2C carry cell)",
            "ffs": ffs,
            "bram_dp16kd": used.get("DP16KD", {}).get("used"),
            "fmax_mhz": round(fmax, 2),
            "fmax_source": f"nextpnr-ecp5 timing analysis of the placed and routed design, clock net {clk_net}",
            "critical_path": ecp5.critical_path(pnr.report, clk_net),
            "clock_constraint_mhz": clock_mhz,
            "timing_met": fmax >= clock_mhz,
            "pair_tests_per_second": round(m * fmax * 1e6),
            "pair_tests_per_second_note": "m * Fmax: m pair tests issue every cycle (peak rate; no stalls)",
            "device_utilisation": used,
            "synth_cells": synthesis.cells,
            "wrapper_cells": wrapper,
            "core_estimate": {
                "luts": luts - comb_cells(wrapper) if luts is not None else None,
                "ffs": ffs - wrapper.get("TRELLIS_FF", 0) if ffs is not None else None,
                "note": "placed totals minus the wrapper synthesised alone around a black-box core",
            },
        },
    }


def not_fitting(pnr: PlaceAndRoute, synthesis: Synthesis) -> dict:
    """What is known of a design that does not fit: what synthesis asked for, not a result."""
    return {
        "status": "does_not_fit",
        "fits": False,
        "result_valid": False,
        "note": "ECP5 place and route stopped: the design does not fit the device. "
                "No ECP5 resource or Fmax numbers exist for this configuration; "
                "'ecp5_demand' is what synthesis asked for, not a result.",
        "ecp5_demand": {
            "device_utilisation_requested": pnr.utilisation,
            "over_capacity": pnr.over_capacity(),
            "nextpnr_error": [l for l in pnr.log.splitlines() if "ERROR" in l][:5],
            "synth_cells": synthesis.cells,
        },
    }


def write_json(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".partial")
    tmp.write_text(json.dumps(data, indent=2, sort_keys=False) + "\n")
    tmp.replace(path)
    log(f"wrote {path}")


def print_summary(r: dict) -> None:
    print(f"== {r['arch']} m={r['m']} capacity={r['capacity']} on {r['part']['ecp5']}")
    if r["status"] == "does_not_fit":
        over = r["ecp5_demand"]["over_capacity"]
        print("   ECP5: DOES NOT FIT: " + (", ".join(f"{k} {v['used']}/{v['available']}" for k, v in over.items())
                                        or "; ".join(r["ecp5_demand"]["nextpnr_error"])))
    else:
        e = r["ecp5"]
        print(f"   ECP5 (placed & routed): {e['luts']} LUT4, {e['ffs']} FF, {e['bram_dp16kd']} DP16KD, "
              f"Fmax {e['fmax_mhz']} MHz (constraint {e['clock_constraint_mhz']:g} MHz, "
              f"{'met' if e['timing_met'] else 'NOT met'})")
        print(f"   pair tests/s = m x Fmax = {e['pair_tests_per_second'] / 1e9:.3f} G")
        mems = r["memories"]  # the binning device's report lists all its memories' mapping only
        print(f"   memories in block RAM: {mems['memories_in_bram']} "
              f"({mems.get('ecp5_mapping', mems.get('ecp5_mapping_all_memories'))})")
    x = r.get("xilinx_estimate")
    if x:
        print(f"   Xilinx xc7 estimate (synthesis only): {x['luts']} LUT, {x['ffs']} FF, "
              f"{x['bram_ramb18e1']} RAMB18E1 + {x['bram_ramb36e1']} RAMB36E1, LUTRAM {x['distributed_ram_cells']}")
    print(f"   runtimes (s): {r['runtime_s']}")
