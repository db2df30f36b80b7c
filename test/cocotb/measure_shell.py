"""Measures the cycles the shell adds to a bench-like CELLS batch (make shell-measure).

One command of CELLS cells whose sizes follow the bench's scene at 8000 objects
(216 cells of about 54 boxes, 11,664 box copies: docs/results.md), sent with no
pause and taken with no back-pressure, on a single-clock shell so that bus and
core cycles are the same. Three numbers:
  - model: the core's own cycles for the batch with a host that offers every
    count and box as soon as the core takes it (BatchTimelineModel, ported);
  - device: the trailer's DEVICE_CYCLES (the core's count through the shell);
  - shell: bus cycles from the first input beat taken to the trailer's TLAST.
The shell adds (device - model) inside the core (the parser's pace) and
(shell - device) around it (the FIFOs, the parser's start, the records' drain
and the trailer)."""

import os
import random
from pathlib import Path

import cocotb
from cocotb.triggers import RisingEdge

from bpaccel_protocol import Cell, brute_force_pairs, cells_words, issue_cycles
from test_shell import CFG, Shell

CELLS = int(os.environ.get("BPACCEL_MEASURE_CELLS", "216"))


def model_cycles(sizes):
    """The core's batch timeline (test/bpaccel/BatchTimelineModel.scala) for a host that never waits."""
    take, last_end, run = 0, -1, 0
    for n in sizes:
        start = max(take + n + 1, last_end + 1)
        busy = CFG.read_latency + CFG.run_overhead_cycles + issue_cycles(n, CFG.m) if 2 <= n <= CFG.capacity else 0
        end = start + busy + 1
        run += busy + 1
        last_end = end
        take = start if CFG.batch_overlaps_loads else end
    return last_end + 1


@cocotb.test(timeout_time=100, timeout_unit="ms")
async def shell_cycles_on_a_bench_like_batch(dut):
    assert not CFG.dual_clock, "measure on a single-clock shell: bus cycles are core cycles"
    s = Shell(dut)
    await s.reset()
    rng = random.Random(7)
    cells = []
    for _ in range(CELLS):
        n = min(CFG.capacity, max(2, round(rng.gauss(54, 14))))
        centre = [rng.randrange(0, 1 << 20) for _ in range(3)]
        boxes = []
        for _ in range(n):
            lo = tuple(c + rng.randrange(0, 400) for c in centre)
            boxes.append((lo, tuple(v + rng.randrange(20, 120) for v in lo)))
        cells.append(Cell(boxes))
    first = None
    async def first_beat():
        nonlocal first
        while not (dut.s_axis_tvalid.value and dut.s_axis_tready.value):
            await RisingEdge(dut.aclk)
        first = cocotb.utils.get_sim_time("ns")
    watch = cocotb.start_soon(first_beat())
    await s.send(cells_words(CFG, cells))
    reply = await s.reply(timeout_us=20000)
    end = cocotb.utils.get_sim_time("ns")
    await watch
    got = {}
    for c, i, j in reply.records:
        got.setdefault(c, set()).add((i, j))
    for c, cell in enumerate(cells):
        assert got.get(c, set()) == brute_force_pairs(cell.boxes), f"cell {c}"
    t = reply.trailer
    sizes = [len(c.boxes) for c in cells]
    model = model_cycles(sizes)
    shell = round((end - first) / 4) + 1
    device = t["DEVICE_CYCLES"]
    dut._log.info(
        f"\nbatch: {len(cells)} cells, {sum(sizes)} boxes, m = {CFG.m}, {CFG.stream_bits}-bit streams, "
        f"{reply.record_count} records, {t['PAIRS']} pairs\n"
        f"model (core alone, host never waits): {model} cycles\n"
        f"device (trailer DEVICE_CYCLES):       {device} cycles ({device - model:+d}: the parser's pace)\n"
        f"shell (first beat in .. TLAST out):   {shell} cycles ({shell - device:+d} around the core)\n"
        f"added by the shell: {shell - model} cycles = {100.0 * (shell - model) / model:.2f} % of the model's")
    Path(os.environ.get("BPACCEL_MEASURE_OUT", "shell_measure.txt")).write_text(
        f"model {model}\ndevice {device}\nshell {shell}\nstall {t['STALL_CYCLES']}\n")
