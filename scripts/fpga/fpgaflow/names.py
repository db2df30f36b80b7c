"""The one rule that names a configuration's folders and reports.

A name is the architecture's prefix (none for the seed, whose reports keep
their names), m, then only what differs from the defaults: the capacity when
one is asked for (the binning device: its box capacity when not its default),
the key width when not the architecture's default (32; the binning device's
12), the memory style when not the flow's, the ECP5 part when not the flow's
(fpgaflow/ecp5.py PARTS). `make` calls this (scripts/fpga/names.py) for its folders and
results/fpga/<name>.json; sweep.py and flow.py import it.
"""
from __future__ import annotations

import json
from pathlib import Path

# The memory style `make fpga` builds unless told otherwise (make verilog's and
# the generator's default too); reports of another carry it as a suffix.
FLOW_MEMORY_STYLE = "inferred"
DEFAULT_KEY_WIDTH = 32
# The binning device's defaults (src/bpaccel/binning/BinningParams.scala), which its names leave out.
BINNING_KEY_WIDTH = 12
BINNING_BOX_CAPACITY = 8192
# The ECP5 part `make fpga` places on unless told otherwise (a key of
# fpgaflow/ecp5.py PARTS); reports of another carry it as a suffix.
DEFAULT_PART = "lfe5u-85f"


def prefix(arch: str) -> str:
    return "" if arch == "seed" else f"{arch}-"


def default_key_width(arch: str) -> int:
    return BINNING_KEY_WIDTH if arch == "binning" else DEFAULT_KEY_WIDTH


def key_suffix(key_width: int, arch: str = "seed") -> str:
    return "" if key_width == default_key_width(arch) else f"-k{key_width}"


def flow_params(params: dict) -> dict:
    """A bpaccel_params.json in the flow's words. The binning device's file (EmitBinning) says
    lanes and box_capacity where the seed's and the stream's say m and capacity."""
    if params.get("arch") != "binning":
        return params
    return dict(params, m=params["lanes"], capacity=params["box_capacity"], default_capacity=BINNING_BOX_CAPACITY)


def design_name(arch: str, m: int, key_width: int | None = None, capacity: int | None = None,
                memory_style: str | None = None, part: str | None = None) -> str:
    """stream-m8, m8 (seed), stream-m64-c4096-k16, stream-m8-ecp5-outreg, stream-m64-lfe5um5g-85f,
    binning-m64-lfe5um5g-85f, ..."""
    name = f"{prefix(arch)}m{m}"
    if capacity is not None:
        name += f"-c{capacity}"
    name += key_suffix(default_key_width(arch) if key_width is None else key_width, arch)
    if memory_style and memory_style != FLOW_MEMORY_STYLE:
        name += f"-{memory_style}"
    if part and part != DEFAULT_PART:
        name += f"-{part}"
    return name


def params_name(params: dict, part: str | None = None) -> str:
    """The name of the design a bpaccel_params.json describes (its capacity named only when not the
    default), placed on `part`."""
    params = flow_params(params)
    capacity = params["capacity"] if params["capacity"] != params["default_capacity"] else None
    return design_name(params["arch"], params["m"], params["key_width"], capacity, params["memory_style"], part)


def sweep_file(arch: str, key_width: int) -> str:
    return f"{prefix(arch)}sweep{key_suffix(key_width)}.json"


def main(argv: list[str] | None = None) -> int:
    import argparse
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--params", type=Path, help="name the design this bpaccel_params.json describes")
    ap.add_argument("--arch")
    ap.add_argument("--m", type=int)
    ap.add_argument("--key-width", type=int, help=f"default {DEFAULT_KEY_WIDTH}, the binning device's {BINNING_KEY_WIDTH}")
    ap.add_argument("--capacity", type=int)
    ap.add_argument("--memory-style")
    ap.add_argument("--part", help=f"ECP5 part (fpgaflow/ecp5.py PARTS; default {DEFAULT_PART})")
    ap.add_argument("--key-suffix", action="store_true", help="print only the key width's suffix")
    args = ap.parse_args(argv)
    if args.key_suffix:
        print(key_suffix(args.key_width or DEFAULT_KEY_WIDTH))
    elif args.params:
        print(params_name(json.loads(args.params.read_text()), args.part))
    elif args.arch and args.m:
        print(design_name(args.arch, args.m, args.key_width, args.capacity, args.memory_style, args.part))
    else:
        ap.error("give --params, or --arch and --m")
    return 0
