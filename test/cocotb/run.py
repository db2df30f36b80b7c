"""Runs the cocotb testbench on an emitted shell with Icarus Verilog.

Usage: run.py VERILOG_DIR [BUILD_DIR]  (VERILOG_DIR holds filelist.f and the headers
that EmitShell writes). Exits non-zero when any test fails."""

import os
import re
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

from cocotb_tools.runner import get_runner

here = Path(__file__).resolve().parent


def main():
    verilog = Path(sys.argv[1]).resolve()
    build = Path(sys.argv[2]).resolve() if len(sys.argv) > 2 else verilog / "cocotb"
    sources = [verilog / line.strip() for line in (verilog / "filelist.f").read_text().split() if line.strip().endswith(".sv")]
    runner = get_runner("icarus")
    start = time.monotonic()
    header = (verilog / "bpaccel_shell.h").read_text()
    defines = {"STREAM_BITS": re.search(r"BPACCEL_SHELL_STREAM_BITS (\d+)", header).group(1)}
    if "BPACCEL_SHELL_DUAL_CLOCK 1" in header:
        defines["DUAL_CLOCK"] = 1
    runner.build(sources=sources + [here / "bpaccel_shell_tb.sv"], hdl_toplevel="bpaccel_shell_tb", build_dir=build,
                 timescale=("1ns", "1ps"), build_args=["-g2012"], defines=defines, always=True)
    results = runner.test(hdl_toplevel="bpaccel_shell_tb", test_module=os.environ.get("BPACCEL_TEST_MODULE", "test_shell"),
                          test_dir=build,
                          test_filter=os.environ.get("BPACCEL_TEST_FILTER"),
                          extra_env={"BPACCEL_SHELL_DIR": str(verilog), "PYTHONPATH": str(here)})
    failures = ET.parse(results).getroot().findall(".//failure") + ET.parse(results).getroot().findall(".//error")
    tests = ET.parse(results).getroot().findall(".//testcase")
    print(f"cocotb on {verilog.name}: {len(tests) - len(failures)} passed, {len(failures)} failed "
          f"in {time.monotonic() - start:.1f} s")
    sys.exit(1 if failures or not tests else 0)


if __name__ == "__main__":
    main()
