"""ECP5 (measured): Yosys synth_ecp5 of the wrapped core, then nextpnr-ecp5 place
and route on one of PARTS (the LFE5U-85F unless told otherwise); resources and
the maximum clock frequency come from nextpnr's own report of the
placed-and-routed design."""
from __future__ import annotations

import json
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

from .design import WRAPPER_TOP, Design
from .names import DEFAULT_PART
from .tools import EXIT_INPUT, EXIT_TOOL, KEEP_REPLICAS, FlowError, Runner, log, memory_mapping, stat_cells


@dataclass(frozen=True)
class Part:
    """An ECP5 part nextpnr-ecp5 places on: its name, the device flag, package and speed grade."""
    key: str          # --part value and report-name suffix (scripts/fpga/fpgaflow/names.py)
    name: str
    device_flag: str
    package: str
    speed: int

    def nextpnr_args(self) -> list[str]:
        return [self.device_flag, "--package", self.package, "--speed", str(self.speed)]

    def text(self) -> str:
        return f"{self.name} {self.package} speed {self.speed} (nextpnr-ecp5 {' '.join(self.nextpnr_args())})"

    def facts(self) -> dict:
        return {"part": self.name, "package": self.package, "speed_grade": self.speed,
                "nextpnr_args": " ".join(self.nextpnr_args())}


# The 85k ECP5 parts in CABGA381, the package of the common 85k boards (ULX3S,
# the ECP5 evaluation boards); only 4 pins are used. The LFE5U-85F has no
# transceivers; the LFE5UM5G-85F has them (5G SERDES), and nextpnr-ecp5 times
# 5G parts at speed grade 8 only.
PARTS = {p.key: p for p in (
    Part("lfe5u-85f", "LFE5U-85F", "--85k", "CABGA381", 6),
    Part("lfe5um5g-85f", "LFE5UM5G-85F", "--um5g-85k", "CABGA381", 8),
)}
assert DEFAULT_PART in PARTS

# How Yosys names a coordinate memory in its log (module mem_<depth>x<width>, instance mem*_ext).
COORD_MEMORY_RE = r"\S*mem\S*"

# The generator's memories with a registered read (src/bpaccel/RegisteredReadMemory.scala,
# memory style ecp5-outreg): the ECP5 run builds them from DP16KD with REGMODE OUTREG.
REGISTERED_MEMORY_PORTS = ["clock", "reset", "io_writeEnable", "io_writeRow", "io_writeData",
                           "io_readEnable", "io_readRow", "io_readData"]
REGISTERED_MEMORY_SOURCE = Path(__file__).resolve().parents[1] / "ecp5" / "Ecp5RegisteredReadMemory.v"


def dp16kd_tiles(rows: int, width: int) -> int:
    """DP16KD that Ecp5RegisteredReadMemory.v uses for one memory (18-bit tiles up to 1024 rows, else 9)."""
    tile = 18 if rows <= 1024 else 9
    return -(-width // tile)


def registered_memory(name: str, rows: int, width: int, ports: dict[str, int]) -> tuple[str, dict]:
    """The ECP5 implementation of the generator's RegisteredReadMemory `name` (DP16KD, REGMODE
    OUTREG) as Verilog, and {module, rows, width, dp16kd}. Its ports (name: width, as Yosys
    read them) must be exactly the generator's: anything else is an error rather than a
    silently different memory."""
    row_bits = max(1, (rows - 1).bit_length())
    expected = dict.fromkeys(REGISTERED_MEMORY_PORTS, 1)
    expected.update(io_writeRow=row_bits, io_readRow=row_bits, io_writeData=width, io_readData=width)
    if ports != expected:
        raise FlowError(EXIT_INPUT, f"{name} has ports {ports}, expected {expected}")
    if rows > 2048:
        raise FlowError(EXIT_INPUT, f"{name}: more than 2048 rows need a DP16KD cascade (not built)")
    source = (
        f"// Written by scripts/fpga/flow.py: {name} of the generator built from DP16KD (REGMODE OUTREG).\n"
        f"module {name}(\n"
        f"  input clock, input reset, input io_writeEnable, input [{row_bits - 1}:0] io_writeRow,\n"
        f"  input [{width - 1}:0] io_writeData, input io_readEnable, input [{row_bits - 1}:0] io_readRow,\n"
        f"  output [{width - 1}:0] io_readData\n);\n"
        f"  Ecp5RegisteredReadMemory #(.ROWS({rows}), .WIDTH({width}), .ROW_BITS({row_bits})) ram (\n"
        f"    .clock(clock), .write_enable(io_writeEnable), .write_row(io_writeRow), .write_data(io_writeData),\n"
        f"    .read_enable(io_readEnable), .read_row(io_readRow), .read_data(io_readData));\n"
        f"endmodule\n")
    return source, {"module": name, "rows": rows, "width": width, "dp16kd": dp16kd_tiles(rows, width)}


def source_files(design: Design) -> tuple[list[str], list[dict]]:
    """The files ECP5 synthesis reads: the emitted ones, with each RegisteredReadMemory (memory
    style ecp5-outreg) replaced by its DP16KD build; and those memories' facts."""
    if not design.registered_memories:
        return list(design.files), []
    if design.params["arch"] == "binning":
        raise FlowError(EXIT_INPUT, "memory style ecp5-outreg of the binning device (two memory modules per group) "
                                    "is not built by the flow: emit it with the inferred style")
    name = design.memory_module
    source, facts = registered_memory(name, design.params["memory_rows"], design.params["memory_width"],
                                      design.modules[name].port_widths())
    ecp5_file = f"ecp5_{name}.v"
    (design.work / ecp5_file).write_text(source)
    shutil.copy2(REGISTERED_MEMORY_SOURCE, design.work / REGISTERED_MEMORY_SOURCE.name)
    files = [ecp5_file if f == f"{name}.sv" else f for f in design.files] + [REGISTERED_MEMORY_SOURCE.name]
    return files, [facts]


@dataclass
class Synthesis:
    files: list[str]            # what synth_ecp5 read
    registered: list[dict]      # the DP16KD builds of RegisteredReadMemory modules
    cells: dict[str, int]       # the wrapped core's cells
    wrapper_cells: dict[str, int]
    memories: dict              # how the coordinate memories were mapped

    def core_cells(self) -> dict[str, int]:
        """Flat synthesis cells of the core: the wrapped run minus the wrapper alone."""
        return {k: v - self.wrapper_cells.get(k, 0) for k, v in self.cells.items() if k != "$scopeinfo"}


def synthesise(runner: Runner, yosys: str, design: Design) -> Synthesis:
    """synth_ecp5 of the wrapped core (ecp5.json for place and route), and of the wrapper alone."""
    files, registered = source_files(design)
    text = runner.yosys("yosys synth_ecp5", yosys, "ecp5",
                        f"read_verilog -sv {' '.join(files)} fpga_wrapper.v\n"
                        f"{KEEP_REPLICAS}"
                        f"synth_ecp5 -top {WRAPPER_TOP} -json ecp5.json\n"
                        f"tee -q -o ecp5_stat.json stat -json\n", "ECP5 synthesis")
    if not (design.work / "ecp5.json").exists():
        raise FlowError(EXIT_TOOL, "ECP5 synthesis wrote no netlist")
    cells, _ = stat_cells(design.work / "ecp5_stat.json")
    return Synthesis(files, registered, cells, wrapper_only(runner, yosys, design),
                     memories(design, cells, text, registered))


def reported_synthesis(runner: Runner, yosys: str, design: Design, report: dict) -> Synthesis:
    """The synthesis an earlier report recorded (its cells), to redo the breakdown alone."""
    files, registered = source_files(design)
    cells = report["ecp5"]["synth_cells"] if report["status"] == "ok" else report["ecp5_demand"]["synth_cells"]
    return Synthesis(files, registered, cells, wrapper_only(runner, yosys, design), report.get("memories", {}))


def wrapper_only(runner: Runner, yosys: str, design: Design) -> dict[str, int]:
    """The wrapper's own cells: the wrapper synthesised around a black-box core."""
    runner.yosys("yosys wrapper-only", yosys, "wrapper",
                 f"read_verilog -sv core_blackbox.v fpga_wrapper.v\n"
                 f"synth_ecp5 -top {WRAPPER_TOP}\n"
                 f"tee -q -o wrapper_stat.json stat -json\n", "synthesis of the wrapper alone")
    cells, _ = stat_cells(design.work / "wrapper_stat.json")
    cells.pop(design.top, None)
    return cells


def memories(design: Design, cells: dict[str, int], text: str, registered: list[dict]) -> dict:
    """Whether every coordinate memory became block RAM (seed: 6m striped memories; stream:
    one of six keys a row), from the synthesis log; the result queue's small memory may
    go to LUT RAM."""
    if design.params["arch"] == "binning":
        return group_memories(design, cells, text)
    n_mems = design.params["memory_count"]
    mapping = memory_mapping(text, COORD_MEMORY_RE)
    dp16 = cells.get("DP16KD", 0)
    if registered:
        # Instantiated, not inferred: every one of the memories is a RegisteredReadMemory.
        instances = design.instance_count(design.memory_module)
        in_bram = instances == n_mems and dp16 >= instances * registered[0]["dp16kd"]
    else:
        bram_mapped = sum(v for k, v in mapping.items() if "16KD" in k)
        in_bram = bram_mapped == n_mems and dp16 >= n_mems and "FF" not in mapping \
            and not any("DPR16X4" in k for k in mapping)
    per_mem = dp16 / n_mems if n_mems else None
    return {
        **mapped_memories(design, in_bram, mapping, "memories"),
        "ecp5_mapping": mapping,
        "ecp5_mapping_all_memories": memory_mapping(text),
        "dp16kd_per_memory": per_mem,
        "memories_in_bram": in_bram,
        "note": memory_note(design, in_bram, per_mem, dp16, registered),
    }


def group_memories(design: Design, cells: dict[str, int], text: str) -> dict:
    """The binning device: whether its group memories (an entry and an order memory per group,
    `memory_count` in all) all became block RAM, from the synthesis log. Its cell tables go to
    LUT RAM by design; the queues' small memories may go to LUT RAM or flip-flops."""
    n_mems, estimate = design.params["memory_count"], design.params["dp16kd_estimate"]
    mapping = memory_mapping(text)
    dp16 = cells.get("DP16KD", 0)
    in_bram = sum(v for k, v in mapping.items() if "16KD" in k) == n_mems
    return {
        **mapped_memories(design, in_bram, mapping, "the group memories"),
        "ecp5_mapping_all_memories": mapping,
        "dp16kd": dp16,
        "dp16kd_estimate": estimate,
        "lut_ram_trellis_dpr16x4": cells.get("TRELLIS_DPR16X4", 0),
        "memories_in_bram": in_bram,
        "note": (f"{n_mems} group memories (entry and order memory of each group) mapped to block RAM: {dp16} "
                 f"DP16KD (BinningParams.dp16kdEstimate: {estimate}); the cell tables in LUT RAM"
                 if in_bram else "the group memories are not all in DP16KD block RAM: see ecp5_mapping_all_memories"),
    }


def mapped_memories(design: Design, in_bram: bool, mapping: dict, what: str) -> dict:
    """The facts every memory report starts with; a warning when `what` are not all in block RAM."""
    if not in_bram:
        log(f"WARNING: {what} did NOT all map to DP16KD block RAM: " + json.dumps(mapping))
    return {"instances": design.params["memory_count"], "module": [design.memory_module],
            "style": design.params["memory_style"]}


def memory_note(design: Design, in_bram: bool, per_mem, dp16: int, registered: list[dict]) -> str:
    if not in_bram:
        return "memories are not all in DP16KD block RAM: see ecp5_mapping"
    if registered:
        return (f"memory style ecp5-outreg: each memory is {registered[0]['dp16kd']} DP16KD instantiated with "
                f"REGMODE_B OUTREG (scripts/fpga/ecp5/Ecp5RegisteredReadMemory.v), {dp16} DP16KD in all")
    if design.params["memory_count"] == 1:
        return f"one memory of six keys a row, {dp16} DP16KD"
    if per_mem == 1:
        return ("each memory has one write and one read port; Yosys maps it to one "
                "pseudo-dual-port DP16KD (512x36), using 256 of its 512 rows")
    if per_mem == 2:
        return ("each memory has one read/write and one read port; Yosys maps it to two "
                "pseudo-dual-port DP16KD (1 write + 1 read port, 512x36), written together, one per "
                "read port: 2 DP16KD per memory, each using 256 of its 512 rows")
    return ""


UTIL_RE = re.compile(r"^Info:\s+(\w+):\s+(\d+)/\s*(\d+)\s+(\d+)%", re.M)
NOFIT_RE = re.compile(r"ERROR:.*(no BELs remaining|not enough|Unable to place|exceed|fit)", re.I)


@dataclass
class PlaceAndRoute:
    fits: bool
    utilisation: dict            # device utilisation, from the report (fit) or the log (no fit)
    log: str
    report: dict | None = None   # nextpnr's JSON report, when it routed

    def over_capacity(self) -> dict:
        return {k: v for k, v in self.utilisation.items() if v["used"] > v["available"]}


def place_and_route(runner: Runner, nextpnr: str, work: Path, part: Part, clock_mhz: float, seed: int,
                    router: str, threads: int, placer: str | None) -> PlaceAndRoute:
    """nextpnr-ecp5 on ecp5.json, placed on `part`: a routed design, or one that does not fit the device."""
    help_text = subprocess.run([nextpnr, "--help"], cwd=work, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True).stdout
    cmd = [nextpnr, *part.nextpnr_args(), "--json", "ecp5.json", "--lpf-allow-unconstrained",
           "--freq", f"{clock_mhz:g}", "--timing-allow-fail", "--seed", str(seed), "--router", router,
           "--report", "nextpnr_report.json"]
    if "--threads" in help_text:
        cmd += ["--threads", str(threads)]
    if placer:
        cmd += ["--placer", placer]
    code, text = runner.run("nextpnr-ecp5", cmd, "nextpnr.log")
    util = {name: {"used": int(used), "available": int(avail)} for name, used, avail, _ in UTIL_RE.findall(text)}
    if code != 0:
        pnr = PlaceAndRoute(False, util, text)
        if pnr.over_capacity() or NOFIT_RE.search(text):
            log("the design does NOT fit the device: " +
                (", ".join(f"{k} {v['used']}/{v['available']}" for k, v in pnr.over_capacity().items())
                 or NOFIT_RE.search(text).group(0)))
            return pnr
        raise FlowError(EXIT_TOOL, "nextpnr-ecp5 failed")
    if "Routing complete" not in text and "Router2 time" not in text and "router1 time" not in text.lower() \
            and not re.search(r"Program finished normally", text):
        raise FlowError(EXIT_TOOL, "nextpnr log does not show a completed route")
    report = json.loads((work / "nextpnr_report.json").read_text())
    if not report.get("fmax"):
        raise FlowError(EXIT_TOOL, "nextpnr report has no fmax entry (clock not found?)")
    used = {k: {"used": v["used"], "available": v["available"]} for k, v in report.get("utilization", {}).items()}
    return PlaceAndRoute(True, used, text, report)


def clock(report: dict) -> tuple[str, float]:
    """The clock net and its achieved Fmax (MHz) in nextpnr's report."""
    entries = report["fmax"]
    net, fm = next(((k, v) for k, v in entries.items() if "clk" in k), next(iter(entries.items())))
    return net, float(fm["achieved"])


def critical_path(report: dict, clk_net: str) -> dict | None:
    """The register-to-register critical path of the clock, from nextpnr's report."""
    for cp in report.get("critical_paths", []):
        if clk_net in cp.get("from", "") and clk_net in cp.get("to", ""):
            path = cp.get("path", [])
            if not path:
                return None
            kinds: dict[str, float] = {}
            for seg in path:
                kinds[seg["type"]] = kinds.get(seg["type"], 0.0) + seg["delay"]
            sources = []
            for seg in path:
                for src in seg.get("sources", []):
                    if not src.startswith("/share") and src not in sources:
                        sources.append(src)

            def carry(seg) -> bool:
                return seg["from"].get("port") == "FCI" or seg["to"].get("port") == "FCO"
            return {
                "delay_ns": round(sum(kinds.values()), 2),
                "routing_ns": round(kinds.get("routing", 0.0), 2),
                "logic_ns": round(sum(v for k, v in kinds.items() if k != "routing"), 2),
                "lut_levels": sum(1 for seg in path if seg["type"] == "logic" and not carry(seg)),
                "carry_cells": sum(1 for seg in path if seg["type"] == "logic" and carry(seg)),
                "from_cell": path[0]["from"]["cell"],
                "to_cell": path[-1]["to"]["cell"],
                "verilog_sources": sources,
            }
    return None


def comb_cells(cells: dict[str, int]) -> int:
    """LUT4 slots: plain LUT4s plus the two LUT halves of each CCU2C carry cell."""
    return cells.get("LUT4", 0) + 2 * cells.get("CCU2C", 0)
