"""The emitted design: its parameters, its files, its structure, and the wrapper
that places it on a device.

Everything about the design comes from two sources, never from reading the
Verilog's text: the generator's parameter file (bpaccel_params.json: arch, m,
capacity, the coordinate memories) and Yosys's own reading of the files
(modules, ports, instances).
"""
from __future__ import annotations

import json
import math
import shutil
from collections import Counter
from pathlib import Path

from .names import flow_params
from .tools import EXIT_INPUT, EXIT_TOOL, FlowError, Runner

WRAPPER_TOP = "FpgaTop"
PARAMS_FILE = "bpaccel_params.json"


def read_params(vdir: Path, m: int | None = None) -> dict:
    """The generator's parameter file beside the Verilog; `m`, when given, must agree."""
    path = vdir / PARAMS_FILE
    if not path.is_file():
        raise FlowError(EXIT_INPUT, f"{path} not found (emit the design with: make verilog VERILOG_DIR={vdir})")
    params = flow_params(json.loads(path.read_text()))
    if m is not None and params["m"] != m:
        raise FlowError(EXIT_INPUT, f"--m {m} but {path} says m = {params['m']}")
    return params


def read_filelist(vdir: Path) -> list[str]:
    fl = vdir / "filelist.f"
    if not fl.is_file():
        raise FlowError(EXIT_INPUT, f"{fl} not found (emit it with: make verilog VERILOG_DIR={vdir})")
    files = [l.strip() for l in fl.read_text().splitlines() if l.strip() and not l.startswith(("//", "#", "-", "+"))]
    for f in files:
        if not (vdir / f).is_file():
            raise FlowError(EXIT_INPUT, f"{vdir / f} listed in filelist.f is missing")
    return files


class Module:
    """One module as Yosys reads it: its ports [(name, direction, width)] and the modules it instantiates."""

    def __init__(self, ports: list[tuple[str, str, int]], instances: Counter):
        self.ports = ports
        self.instances = instances

    def port_widths(self) -> dict[str, int]:
        return {n: w for n, _, w in self.ports}


class Design:
    """The emitted configuration, copied into the work dir (the WebAssembly tools
    see /tmp as a private dir, so they work on copies)."""

    def __init__(self, vdir: Path, work: Path, m: int | None = None):
        self.vdir = vdir
        self.params = read_params(vdir, m)
        self.files = read_filelist(vdir)
        self.work = work
        work.mkdir(parents=True, exist_ok=True)
        for f in self.files:
            shutil.copy2(vdir / f, work / f)
        self.modules: dict[str, Module] = {}

    @property
    def top(self) -> str:
        return self.params["top"]

    @property
    def m(self) -> int:
        return self.params["m"]

    @property
    def memory_module(self) -> str:
        """The coordinate memories' module: one per memory, `memory_count` instances in all."""
        return self.params["memory_module"]

    @property
    def registered_memories(self) -> bool:
        """Memory style ecp5-outreg: the memories are RegisteredReadMemory modules the ECP5 run replaces."""
        return self.params["memory_style"] == "ecp5-outreg"

    def read_structure(self, runner: Runner, yosys: str) -> None:
        """Modules, ports and instances, from Yosys's reading of the files."""
        code, _ = runner.run("yosys structure", [yosys, "-q", "-p",
                                                 f"read_verilog -sv {' '.join(self.files)}; "
                                                 f"hierarchy -top {self.top}; proc; write_json structure.json"],
                             "structure.log")
        if code != 0 or not (self.work / "structure.json").exists():
            raise FlowError(EXIT_TOOL, "yosys could not read the design")
        mods = json.loads((self.work / "structure.json").read_text())["modules"]
        self.modules = {
            name.lstrip("\\"): Module(
                [(p, d["direction"], len(d["bits"])) for p, d in mod["ports"].items()],
                Counter(c["type"].lstrip("\\") for c in mod["cells"].values() if not c["type"].startswith("$")))
            for name, mod in mods.items()}
        for needed in (self.top, self.memory_module):
            if needed not in self.modules:
                raise FlowError(EXIT_INPUT, f"no module {needed} in {self.vdir}/filelist.f, "
                                            f"which {PARAMS_FILE} names")

    def instance_count(self, module: str) -> int:
        return sum(m.instances[module] for m in self.modules.values())

    def instantiates(self, parent: str, child: str) -> bool:
        return self.modules[parent].instances[child] > 0 if parent in self.modules else False

    def write_wrapper(self) -> dict:
        """Writes fpga_wrapper.v and core_blackbox.v for the top's ports; returns the wrapper's facts."""
        ports = self.modules[self.top].ports
        source, info = wrapper(self.top, ports)
        (self.work / "fpga_wrapper.v").write_text(source)
        (self.work / "core_blackbox.v").write_text(blackbox_stub(self.top, ports))
        return info


def wrapper(top: str, ports: list[tuple[str, str, int]]) -> tuple[str, dict]:
    """A four-pin wrapper (clk, rst_in, sin, sout) around the core, whose ~560 ports no
    ECP5 package has pins for: every core input is one flip-flop of a shift register fed
    from `sin`, every output goes into a pipelined, registered XOR tree ending at `sout`.
    Nothing of the core can be optimised away, and every path into and out of it is
    register to register."""
    names = {n for n, _, _ in ports}
    if not {"clock", "reset"} <= names:
        raise FlowError(EXIT_INPUT, f"{top} has no clock/reset ports")
    bad = [n for n, d, _ in ports if d not in ("input", "output")]
    if bad:
        raise FlowError(EXIT_INPUT, f"unsupported port directions: {bad}")
    ins = [(n, w) for n, d, w in ports if d == "input" and n not in ("clock", "reset")]
    outs = [(n, w) for n, d, w in ports if d == "output"]
    ni, no = sum(w for _, w in ins), sum(w for _, w in outs)
    conns = [".clock(clk)", ".reset(rst_q)"]
    for bus, group in (("in_q", ins), ("core_out", outs)):
        pos = 0
        for n, w in group:
            conns.append(f".{n}({bus}[{pos + w - 1}:{pos}])")
            pos += w
    # Pipelined XOR tree, fan-in 4 (one LUT4 per node, one register level per tree level).
    levels, body = [], []
    prev, width, lvl = "core_out", no, 0
    while True:
        nxt = math.ceil(width / 4)
        body.append(f"  reg [{nxt - 1}:0] x{lvl};")
        body.append("  always @(posedge clk) begin")
        for i in range(nxt):
            body.append(f"    x{lvl}[{i}] <= ^{prev}[{min(4 * i + 3, width - 1)}:{4 * i}];")
        body.append("  end")
        levels.append(nxt)
        prev, width, lvl = f"x{lvl}", nxt, lvl + 1
        if nxt == 1:
            break
    nl = "\n"
    src = f"""// Generated by scripts/fpga/flow.py: four-pin wrapper for place and route.
// Every input of {top} is one flip-flop of a {ni}-bit shift register fed from
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
  {top} core (
    {(',' + nl + '    ').join(conns)}
  );
{nl.join(body)}
  assign sout = {prev}[0];
endmodule

"""
    info = {"pins": 4, "core_input_bits": ni, "core_output_bits": no, "shift_register_ffs": ni,
            "xor_tree_levels": len(levels), "xor_tree_nodes": sum(levels)}
    return src, info


def blackbox_stub(top: str, ports) -> str:
    decl = [f"  {d} {'[%d:0] ' % (w - 1) if w > 1 else ''}{n}" for n, d, w in ports]
    return f"(* blackbox *)\nmodule {top} (\n" + ",\n".join(decl) + "\n);\nendmodule\n"
