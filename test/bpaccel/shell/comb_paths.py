"""Finds combinational paths from input ports to output ports of an emitted design.

Usage: comb_paths.py VERILOG_DIR TOP [BLACK_BOX ...]
Yosys reads the files of VERILOG_DIR/filelist.f and flattens TOP to gates
(proc; flatten; memory -nomap; techmap; write_json); modules named as black
boxes count as logic from each of their inputs to each of their outputs,
more paths than they have, so none found is still a proof. Prints each path
found, exits 1 if any.

Every cell is combinational from all its inputs to all its outputs except
flip-flops and latches (state: a path ends there) and memories, whose
synchronous read ports and write ports break the path while an asynchronous
read port passes its address to its data."""

import json
import subprocess
import sys
from pathlib import Path
from collections import defaultdict

SEQUENTIAL = ("$_DFF", "$_SDFF", "$_DFFE", "$_SDFFE", "$_SDFFCE", "$_ALDFF", "$_DFFSR", "$_DLATCH", "$_SR_",
              "$dff", "$adff", "$sdff", "$dffe", "$adffe", "$sdffe", "$sdffce", "$aldff", "$aldffe", "$dffsr",
              "$dffsre", "$dlatch", "$adlatch", "$sr")


def edges(module):
    """Bit-level edges of the combinational cells: input net bit -> output net bits."""
    out = defaultdict(set)
    for cell in module["cells"].values():
        kind, conns, dirs = cell["type"], cell["connections"], cell.get("port_directions", {})
        if kind.startswith(SEQUENTIAL):
            continue
        if kind == "$mem_v2":
            p = cell["parameters"]
            ports, abits, wbits = int(p["RD_PORTS"], 2), int(p["ABITS"], 2), int(p["WIDTH"], 2)
            clocked = int(p["RD_CLK_ENABLE"], 2) if p["RD_CLK_ENABLE"] else 0
            for r in range(ports):
                if not clocked >> r & 1:
                    addr = conns["RD_ADDR"][r * abits:(r + 1) * abits]
                    data = conns["RD_DATA"][r * wbits:(r + 1) * wbits]
                    for a in addr:
                        out[a].update(data)
            continue
        ins = [b for port, bits in conns.items() if dirs.get(port) == "input" for b in bits]
        outs = [b for port, bits in conns.items() if dirs.get(port) == "output" for b in bits]
        for i in ins:
            out[i].update(outs)
    return out


def paths(netlist, top):
    module = netlist["modules"][top]
    graph = edges(module)
    names = {}
    for name, port in module["ports"].items():
        for b in port["bits"]:
            names[b] = name
    inputs = {n: p["bits"] for n, p in module["ports"].items() if p["direction"] == "input"}
    outputs = {b for p in module["ports"].values() if p["direction"] == "output" for b in p["bits"]}
    found = set()
    for name, bits in inputs.items():
        seen, stack = set(), [b for b in bits if isinstance(b, int)]
        while stack:
            b = stack.pop()
            if b in seen:
                continue
            seen.add(b)
            if b in outputs:
                found.add((name, names[b]))
            stack.extend(graph.get(b, ()))
    return sorted(found)


def netlist(verilog_dir: Path, top: str, black_boxes) -> dict:
    files = [f for f in (verilog_dir / "filelist.f").read_text().split() if f.endswith(".sv")]
    out = verilog_dir.resolve() / f"{top}.netlist.json"
    boxes = "".join(f"blackbox {b}; " for b in black_boxes)
    script = (f"read_verilog -sv {' '.join(files)}; {boxes}hierarchy -top {top}; proc; flatten; memory -nomap; "
              f"opt_clean; techmap; opt_clean; write_json {out}")
    subprocess.run(["yosys", "-q", "-p", script], cwd=verilog_dir, check=True)
    with open(out) as f:
        return json.load(f)


if __name__ == "__main__":
    top = sys.argv[2]
    found = paths(netlist(Path(sys.argv[1]), top, sys.argv[3:]), top)
    for a, b in found:
        print(f"combinational path: {a} -> {b}")
    sys.exit(1 if found else 0)
