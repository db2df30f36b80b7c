"""The AXI shell driven as a DMA engine and a CPU drive it (docs/integration.md):
CELLS commands on the input stream, replies on the output stream, registers
and the interrupt over AXI4-Lite; pairs checked against brute force."""

import os
import random
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge, with_timeout
from cocotbext.axi import AxiLiteBus, AxiLiteMaster, AxiResp, AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

from coverage import Coverage
from bpaccel_protocol import Cell, Config, brute_force_pairs, cells_words, decode_reply, issue_cycles, to_packet

CFG = Config.load(Path(os.environ["BPACCEL_SHELL_DIR"]))
SEED = int(os.environ.get("BPACCEL_SEED", "1"))
MAX_KEY = (1 << CFG.key_width) - 1


def _required():
    points = ["input back-pressure", "output back-pressure", "write response back-pressure", "irq raised",
              "irq cleared by W1C", "trailer after a partial beat", "several commands queued",
              "empty command", "empty cell", "one-box cell", "full cell", "more cells than the core queues",
              "core batch restarted", "abort mid-packet", "abort during a reply", "abort when idle",
              "soft reset mid-packet", "soft reset during a reply", "counter read lo then hi", "SLVERR"]
    errors = ["BAD_COMMAND", "LENGTH_MISMATCH", "COUNT_OVER_CAPACITY", "ABORTED"]
    errors.append("SPLIT_OUT_OF_RANGE" if CFG.bipartite_runs else "SPLIT_UNSUPPORTED")
    if CFG.key_width < CFG.key_slot_bits:
        errors.append("KEY_TOO_WIDE")
    if CFG.bipartite_runs:
        points.append("bipartite cell")
    if CFG.words_per_beat % CFG.record_words:
        points.append("record crosses a beat")
    return points + [f"error {e}" for e in errors]


COVERAGE = Coverage(_required())


def resume(channel):
    """Stops a channel's pauses (clearing the generator leaves its last value)."""
    channel.clear_pause_generator()
    channel.pause = False


def pauses(probability, rng):
    while True:
        yield rng.random() < probability


class Shell:
    """The testbench's DMA engine (two stream channels), CPU (AXI4-Lite) and checkers."""

    def __init__(self, dut):
        self.dut = dut
        self.rng = random.Random(SEED)
        Clock(dut.aclk, 4, unit="ns").start()
        if CFG.dual_clock:
            Clock(dut.core_clk, 5.6, unit="ns").start()  # slower than the bus, unrelated
        self.source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis"), dut.aclk, dut.aresetn, reset_active_level=False)
        self.sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis"), dut.aclk, dut.aresetn, reset_active_level=False)
        self.axil = AxiLiteMaster(AxiLiteBus.from_prefix(dut, "s_axil"), dut.aclk, dut.aresetn, reset_active_level=False)
        self.violations_before = int(dut.violations.value)

    async def reset(self):
        self.dut.aresetn.value = 0
        await ClockCycles(self.dut.aclk, 5)
        self.dut.aresetn.value = 1
        await self.wait_ready()

    async def wait_ready(self):
        for _ in range(200):
            if CFG.field("STATUS", "READY", await self.read("STATUS")):
                return
            await ClockCycles(self.dut.aclk, 2)
        raise AssertionError("STATUS.READY did not rise")

    def backpressure(self, probability):
        """Random pauses on both streams and the write responses (probability per cycle)."""
        for channel in (self.source, self.sink, self.axil.write_if.b_channel):
            if probability:
                channel.set_pause_generator(pauses(probability, self.rng))
            else:
                resume(channel)

    async def read(self, name):
        return await self.axil.read_dword(CFG.reg(name))

    async def write(self, name, value):
        await self.axil.write_dword(CFG.reg(name), value)

    async def counter(self, name):
        lo = await self.read(f"{name}_LO")
        hi = await self.read(f"{name}_HI")
        COVERAGE.hit("counter read lo then hi")
        return lo | hi << 32

    async def send(self, words):
        await self.source.send(AxiStreamFrame(to_packet(CFG, words)))

    async def reply(self, timeout_us=300):
        frame = await with_timeout(self.sink.recv(), timeout_us, "us")
        reply = decode_reply(CFG, bytes(frame.tdata))
        COVERAGE.hit("trailer after a partial beat", any(w == 0 for w in reply.fill_words) and len(reply.fill_words) > 0)
        rw, k = CFG.record_words, CFG.words_per_beat
        if "record crosses a beat" in COVERAGE.hits:
            COVERAGE.hit("record crosses a beat", any((r * rw) // k != (r * rw + rw - 1) // k for r in range(reply.record_count)))
        assert all(w == 0 for w in reply.fill_words), "the words between the records and the trailer are not zero"
        if reply.error:
            COVERAGE.hit(f"error {_error_name(reply.error)}")
        return reply

    async def run(self, cells):
        """One good CELLS command: sends it, checks every pair and the trailer; returns the reply."""
        await self.send(cells_words(CFG, cells))
        reply = await self.reply()
        check_cells(cells, reply)
        return reply

    async def gaps_before(self, beats, cycles):
        """Holds the input for `cycles` before each beat (index in the next packet) of `beats`: a DMA that
        waits for memory. The pause is set while the beat before is on the bus, so it lands exactly."""
        d, sent = self.dut, 0
        while True:
            await FallingEdge(d.aclk)
            if d.s_axis_tvalid.value and d.s_axis_tready.value:
                sent += 1
                if sent in beats:
                    self.source.pause = True
                    await ClockCycles(d.aclk, cycles)
                    self.source.pause = False

    async def hold_after(self, channel, prefix, beats):
        """Pauses a stream channel once `beats` more beats have passed on the `prefix` interface."""
        d, passed = self.dut, 0
        valid, ready = getattr(d, f"{prefix}_tvalid"), getattr(d, f"{prefix}_tready")
        while passed < beats:
            await FallingEdge(d.aclk)
            passed += bool(valid.value and ready.value)
        channel.pause = True

    def check_protocol(self):
        """The protocol checkers of bpaccel_shell_tb.sv found nothing; their corner-case counters go to coverage."""
        d = self.dut
        COVERAGE.hit("input back-pressure", int(d.input_stalls.value) > 0)
        COVERAGE.hit("output back-pressure", int(d.output_stalls.value) > 0)
        COVERAGE.hit("write response back-pressure", int(d.response_stalls.value) > 0)
        found = int(d.violations.value) - self.violations_before
        assert found == 0, f"{found} AXI protocol violations (see the log)"


async def started(dut, stream):
    """A shell out of reset, and the random numbers of one test (`stream` keeps each test's own)."""
    s = Shell(dut)
    await s.reset()
    return s, random.Random(SEED + stream)


def _error_name(code):
    return next(k[len("BPACCEL_SHELL_ERR_"):] for k, v in CFG.defines.items() if k.startswith("BPACCEL_SHELL_ERR_") and v == code)


def check_cells(cells, reply, error=0):
    t = reply.trailer
    assert reply.error == error, f"error {reply.error} ({_error_name(reply.error)}), expected {error}"
    assert t["HEADER"] >> 16 & 0xFF == CFG.op_cells
    if error:
        return
    got = {}
    for cell, i, j in reply.records:
        assert i < j < len(cells[cell].boxes), f"pair ({i}, {j}) of cell {cell} out of range"
        assert (i, j) not in got.setdefault(cell, set()), f"pair ({i}, {j}) of cell {cell} reported twice"
        got[cell].add((i, j))
    for c, cell in enumerate(cells):
        assert got.get(c, set()) == brute_force_pairs(cell.boxes, cell.split), f"cell {c}: wrong pairs"
    assert t["PAIRS"] == len(reply.records)
    assert t["BOXES"] == sum(len(c.boxes) for c in cells)
    assert t["CELLS"] == len(cells)
    assert t["ISSUE_CYCLES"] == sum(issue_cycles(len(c.boxes), CFG.m, c.split) for c in cells)
    assert t["DETAIL"] == 0 and t["RESERVED"] == 0
    assert t["DEVICE_CYCLES"] >= t["INTAKE_CYCLES"] + t["ISSUE_CYCLES"] + t["STALL_CYCLES"]


def header_words(cells):
    """Word index of each cell's header in its CELLS command."""
    at, out = 2, []
    for c in cells:
        out.append(at)
        at += 2 + len(c.boxes) * CFG.box_words
    return out


def cells_on_beat_boundaries(rng, count):
    """Cells of 1 .. 16 boxes whose headers (but the first) each start a beat."""
    cells, at = [], 4
    for _ in range(count):
        n = next(n for n in range(1, 17) if (at + n * CFG.box_words) % CFG.words_per_beat == 0)
        cells.append(Cell(scene(rng, n, "dense")))
        at += n * CFG.box_words + 2
    return cells


def random_box(rng, span, extent):
    lo = [rng.randrange(0, span) for _ in range(3)]
    hi = [min(MAX_KEY, v + rng.randrange(0, extent + 1)) for v in lo]
    return (tuple(lo), tuple(hi))


def scene(rng, n, kind=None):
    kind = kind or rng.choice(["dense", "sparse", "touching", "extremes"])
    if kind == "dense":
        return [random_box(rng, 40, 15) for _ in range(n)]
    if kind == "sparse":
        return [random_box(rng, MAX_KEY, MAX_KEY // 8) for _ in range(n)]
    if kind == "touching":
        out = []
        for _ in range(n):
            lo = [10 * rng.randrange(4) for _ in range(3)]
            out.append((tuple(lo), tuple(v + rng.choice([0, 10]) for v in lo)))
        return out
    out = []
    for _ in range(n):
        lo = [rng.choice([0, MAX_KEY - rng.randrange(3)]) for _ in range(3)]
        out.append((tuple(lo), tuple(rng.choice([v, MAX_KEY]) for v in lo)))
    return out


def random_cells(rng, count, max_boxes=None):
    max_boxes = max_boxes or CFG.capacity
    cells = []
    for _ in range(count):
        n = rng.choice([0, 1, 2, rng.randrange(2, max_boxes + 1), max_boxes])
        split = rng.randrange(1, n) if CFG.bipartite_runs and n >= 2 and rng.random() < 0.3 else 0
        cells.append(Cell(scene(rng, n), split))
        COVERAGE.hit("empty cell", n == 0)
        COVERAGE.hit("one-box cell", n == 1)
        COVERAGE.hit("full cell", n == CFG.capacity)
        COVERAGE.hit("bipartite cell", split != 0) if CFG.bipartite_runs else None
    return cells


@cocotb.test(timeout_time=1000, timeout_unit="us")
async def registers_describe_the_configuration(dut):
    """ID, versions, fingerprint and capabilities equal the C header; RW, W1C and SLVERR behave."""
    s = Shell(dut)
    await s.reset()
    assert await s.read("ID") == 0x43415042
    assert CFG.field("VERSION", "PROTOCOL", await s.read("VERSION")) == CFG.protocol_version
    assert await s.read("FINGERPRINT") == CFG.fingerprint
    for reg, expected in [("LANES", CFG.m), ("CAPACITY", CFG.capacity), ("KEY_WIDTH", CFG.key_width),
                          ("INDEX_WIDTH", CFG.index_width), ("STREAM_BITS", CFG.stream_bits),
                          ("BATCH_CELLS", CFG.batch_cells), ("ARCH", CFG.arch_id), ("OPCODES", 1 << CFG.op_cells)]:
        assert await s.read(reg) == expected, reg
    fmt = await s.read("FORMAT")
    assert CFG.field("FORMAT", "BOX_WORDS", fmt) == CFG.box_words
    assert CFG.field("FORMAT", "RECORD_WORDS", fmt) == CFG.record_words
    # Read-write with byte strobes; read-only ignores writes; W1C of a clear bit stays clear.
    await s.write("IRQ_ENABLE", 3)
    assert await s.read("IRQ_ENABLE") == 3
    await s.axil.write(CFG.reg("IRQ_ENABLE") + 1, b"\x00")  # byte 1 only: bits 1:0 keep their value
    assert await s.read("IRQ_ENABLE") == 3
    await s.write("IRQ_ENABLE", 0)
    await s.write("LANES", 0)
    assert await s.read("LANES") == CFG.m
    # Unmapped and unaligned addresses answer SLVERR.
    for addr in (0xFFC, CFG.reg("STATUS") + 2):
        assert (await s.axil.read(addr, 4)).resp == AxiResp.SLVERR
        COVERAGE.hit("SLVERR")
    assert (await s.axil.write(0x0F0, b"\x01\x00\x00\x00")).resp == AxiResp.SLVERR
    status = await s.read("STATUS")
    assert CFG.field("STATUS", "BUSY", status) == 0 and CFG.field("STATUS", "READY", status) == 1
    s.check_protocol()


@cocotb.test(timeout_time=1000, timeout_unit="us")
async def pairs_match_brute_force_under_back_pressure(dut):
    """Random commands, several queued at once, random pauses on every stream; register counters add up."""
    s, rng = await started(dut, 1)
    commands = [random_cells(rng, rng.randrange(1, 6)) for _ in range(16)]
    totals = {"PAIRS": 0, "BOXES": 0, "ISSUE_CYCLES": 0, "RECORDS": 0}
    for round_, probability in enumerate([0.0, 0.5]):
        s.backpressure(probability)
        batch = commands[8 * round_:8 * round_ + 8]
        for cells in batch:
            cocotb.start_soon(s.send(cells_words(CFG, cells)))  # queued behind each other, as a DMA ring does
        await s.write("IRQ_ENABLE", 0)  # a register write while the write responses are held back too
        COVERAGE.hit("several commands queued", CFG.field("STATUS", "BUSY", await s.read("STATUS")) == 1)
        for cells in batch:
            reply = await s.reply()
            check_cells(cells, reply)
            if probability == 0.0 and CFG.words_per_beat >= CFG.record_words:
                assert reply.trailer["STALL_CYCLES"] == 0, "stalls with an output that never waits and keeps up"
            for k in ("PAIRS", "BOXES", "ISSUE_CYCLES"):
                totals[k] += reply.trailer[k]
            totals["RECORDS"] += reply.record_count
    s.backpressure(0)
    assert await s.counter("REPLIES") == len(commands)
    assert await s.counter("ERRORS") == 0
    for k, v in totals.items():
        assert await s.counter(k) == v, k
    s.check_protocol()


@cocotb.test(timeout_time=1000, timeout_unit="us")
async def corner_cases_of_cells(dut):
    """No cells, empty cells, more cells than the core queues, and input that runs dry between cells."""
    s, rng = await started(dut, 2)
    reply = await s.run([])
    COVERAGE.hit("empty command")
    assert reply.record_count == 0 and reply.trailer["CELLS"] == 0
    await s.run([Cell([]), Cell(scene(rng, 1)), Cell([])])
    await s.run([Cell(scene(rng, CFG.capacity, "dense")), Cell(scene(rng, CFG.capacity, "sparse"))])
    COVERAGE.hit("full cell")
    many = [Cell(scene(rng, rng.randrange(0, 4), "dense")) for _ in range(CFG.batch_cells + 6)]
    await s.run(many)
    COVERAGE.hit("more cells than the core queues")
    # A DMA that pauses between cells: the core ends its batch and begins another, the reply stays one.
    cells = cells_on_beat_boundaries(rng, 4)
    batches = 0
    batch = dut.shell.core.adapter.core.io_status_batch
    async def count_batches():
        nonlocal batches
        was = 0
        while True:
            await RisingEdge(dut.shell.core.adapter.core.clock)
            now = int(batch.value)
            batches += now and not was
            was = now
    counting = cocotb.start_soon(count_batches())
    words = cells_words(CFG, cells)
    headers = header_words(cells)
    gaps = cocotb.start_soon(s.gaps_before(set(h // CFG.words_per_beat for h in headers[1:]), 200))
    await s.send(words)
    check_cells(cells, await s.reply())
    gaps.cancel()
    counting.cancel()
    COVERAGE.hit("core batch restarted", batches > 1)
    assert batches > 1, "the pauses did not restart the core's batch"
    s.check_protocol()


@cocotb.test(timeout_time=1000, timeout_unit="us")
async def errors_name_what_and_where(dut):
    """Each error ends its command with a trailer naming it; the next command is right."""
    s, rng = await started(dut, 3)
    good = [Cell(scene(rng, 6, "dense")), Cell(scene(rng, 3, "dense"))]
    words = cells_words(CFG, good)
    box = CFG.box_words
    err = CFG.error

    async def expect(words_sent, code, detail=None):
        await s.send(words_sent)
        reply = await s.reply()
        assert reply.error == code, f"error {_error_name(reply.error)}, expected {_error_name(code)}"
        if detail is not None:
            assert reply.trailer["DETAIL"] == detail, f"detail {reply.trailer['DETAIL']}, expected {detail}"
        await s.run(good)  # the device recovers
        return reply

    await expect([CFG.op_frame | 1 << 8, 0, 0, 0], err("BAD_COMMAND"))             # the other architectures' opcode
    await expect([0x7F | 1 << 8] + [0] * 9, err("BAD_COMMAND"))                     # unknown opcode, several beats
    await expect([CFG.op_cells | 2 << 8, 0], err("BAD_COMMAND"))                     # version 2
    await expect([CFG.op_cells | 1 << 8 | 1 << 20, 0], err("BAD_COMMAND"))           # nonzero bits [31:16]
    await expect(words[:2 + 2 + 3 * box + 2], err("LENGTH_MISMATCH"), 0)            # cut inside a box of cell 0
    await expect(words[:2 + 2 + 6 * box + 2], err("LENGTH_MISMATCH"), 1)            # cut after cell 1's header
    await expect(words + [0] * CFG.words_per_beat, err("LENGTH_MISMATCH"), 2)       # a beat too many
    # More cells promised than sent: the zero padding reads as empty cells' headers until TLAST cuts one.
    pad = -len(words) % CFG.words_per_beat
    await expect(cells_words(CFG, good, cell_count=len(good) + CFG.words_per_beat), err("LENGTH_MISMATCH"),
                 len(good) - 1 + (pad + 1) // 2)
    if len(words) % CFG.words_per_beat:
        await expect(words + [5], err("LENGTH_MISMATCH"), 2)                          # nonzero padding
    await expect(cells_words(CFG, [good[0], Cell(scene(rng, 2), count=CFG.capacity + 1)]),
                 err("COUNT_OVER_CAPACITY"), 1)
    if CFG.bipartite_runs:
        await expect(cells_words(CFG, [Cell(scene(rng, 4), split=4)]), err("SPLIT_OUT_OF_RANGE"), 0)
    else:
        await expect(cells_words(CFG, [Cell(scene(rng, 4), split=1)]), err("SPLIT_UNSUPPORTED"), 0)
    if CFG.key_width < CFG.key_slot_bits:
        wide = good[0].boxes[:3] + [((0, 1 << CFG.key_width, 0), (5, 5, 5))]
        await expect(cells_words(CFG, [good[1], Cell(wide)]), err("KEY_TOO_WIDE"), len(good[1].boxes) + 3)
    assert await s.counter("ERRORS") >= 10
    detail = await s.read("LAST_DETAIL")
    assert detail == 0
    s.check_protocol()


async def _wait_status(s, field, value, cycles=2000):
    for _ in range(cycles):
        if CFG.field("STATUS", field, await s.read("STATUS")) == value:
            return
    raise AssertionError(f"STATUS.{field} did not become {value}")


@cocotb.test(timeout_time=1000, timeout_unit="us")
async def abort_ends_the_command_with_a_trailer(dut):
    """Abort mid-packet and during a stalled reply: records so far, then ABORTED; the device goes on."""
    s, rng = await started(dut, 4)
    aborted = CFG.error("ABORTED")
    cells = [Cell(scene(rng, CFG.capacity, "dense")) for _ in range(3)]
    # Mid-packet: the DMA sends the first beats, then stalls.
    packet = to_packet(CFG, cells_words(CFG, cells))
    holding = cocotb.start_soon(s.hold_after(s.source, "s_axis", 6))
    sending = cocotb.start_soon(s.source.send(AxiStreamFrame(packet)))
    await holding
    await _wait_status(s, "IN_PACKET", 1)
    await ClockCycles(dut.aclk, 30)
    await s.write("CONTROL", 1 << CFG.defines["BPACCEL_SHELL_REG_CONTROL_ABORT_SHIFT"])
    reply = await s.reply()
    COVERAGE.hit("abort mid-packet")
    assert reply.error == aborted
    resume(s.source)  # the rest of the packet arrives and is drained
    await sending
    await s.run(cells[:1])
    # During a reply the host does not take.
    holding = cocotb.start_soon(s.hold_after(s.sink, "m_axis", 2))
    await s.send(cells_words(CFG, cells))
    await holding
    await _wait_status(s, "REPLY_OPEN", 1)
    await s.write("CONTROL", 1)
    resume(s.sink)
    reply = await s.reply()
    COVERAGE.hit("abort during a reply")
    assert reply.error in (aborted, 0)  # the command may have finished before the abort reached it
    # Idle: nothing happens, no reply.
    await s.write("CONTROL", 1)
    await ClockCycles(dut.aclk, 50)
    assert s.sink.empty()
    COVERAGE.hit("abort when idle")
    await s.run(cells[1:])
    s.check_protocol()


@cocotb.test(timeout_time=1000, timeout_unit="us")
async def soft_reset_recovers_mid_frame(dut):
    """Soft reset with a packet half sent and with a reply half taken; the driver resets its DMA too."""
    s, rng = await started(dut, 5)
    cells = [Cell(scene(rng, CFG.capacity, "dense")) for _ in range(3)]
    await s.write("IRQ_ENABLE", 1)
    for case, stall in (("soft reset mid-packet", s.source), ("soft reset during a reply", s.sink)):
        prefix = "s_axis" if stall is s.source else "m_axis"
        holding = cocotb.start_soon(s.hold_after(stall, prefix, 3))
        cocotb.start_soon(s.send(cells_words(CFG, cells)))
        await holding
        await _wait_status(s, "IN_PACKET" if stall is s.source else "REPLY_OPEN", 1)
        # What a driver does: halt and flush its DMA channels, soft reset, wait for READY, restart the DMA.
        dut.stream_reset.value = 1
        for channel in (s.source, s.sink):
            channel.clear_pause_generator()
            channel.pause = True
            channel.clear()
            channel._handle_reset(True)
            channel._handle_reset(False)
        await s.write("CONTROL", 1 << CFG.defines["BPACCEL_SHELL_REG_CONTROL_SOFT_RESET_SHIFT"])
        await s.wait_ready()
        dut.stream_reset.value = 0
        for channel in (s.source, s.sink):
            resume(channel)
        status = await s.read("STATUS")
        assert CFG.field("STATUS", "BUSY", status) == 0 and CFG.field("STATUS", "REPLY_OPEN", status) == 0
        assert await s.counter("REPLIES") == 0, "a soft reset clears the counters"
        assert await s.read("IRQ_ENABLE") == 1, "a soft reset keeps IRQ_ENABLE"
        COVERAGE.hit(case)
        await s.run(cells[:2])
    s.check_protocol()


@cocotb.test(timeout_time=1000, timeout_unit="us")
async def interrupt_follows_enable_and_w1c(dut):
    """The line rises for an enabled cause only, and falls when the cause is cleared."""
    s, rng = await started(dut, 6)
    cells = [Cell(scene(rng, 4, "dense"))]
    await s.write("IRQ_STATUS", 3)
    await s.write("IRQ_ENABLE", 0)
    await s.run(cells)
    await ClockCycles(dut.aclk, 4)
    assert dut.irq.value == 0
    assert CFG.field("IRQ_STATUS", "REPLY", await s.read("IRQ_STATUS")) == 1
    await s.write("IRQ_ENABLE", 1)
    await ClockCycles(dut.aclk, 4)
    assert dut.irq.value == 1
    COVERAGE.hit("irq raised", int(dut.irq_rises.value) > 0)
    await s.write("IRQ_STATUS", 1)
    await ClockCycles(dut.aclk, 4)
    assert dut.irq.value == 0
    COVERAGE.hit("irq cleared by W1C")
    # ERROR only: a good command raises nothing, a bad one does.
    await s.write("IRQ_ENABLE", 2)
    await s.run(cells)
    await ClockCycles(dut.aclk, 4)
    assert dut.irq.value == 0
    await s.send([0x7F, 0])
    await s.reply()
    await ClockCycles(dut.aclk, 4)
    assert dut.irq.value == 1
    assert CFG.field("IRQ_STATUS", "ERROR", await s.read("IRQ_STATUS")) == 1
    await s.write("IRQ_STATUS", 3)
    await ClockCycles(dut.aclk, 4)
    assert dut.irq.value == 0
    s.check_protocol()


@cocotb.test(timeout_time=1000, timeout_unit="us")
async def every_corner_case_was_reached(dut):
    """The coverage points of the suite (runs last)."""
    dut._log.info("coverage:\n" + COVERAGE.report())
    assert not COVERAGE.missed(), f"coverage points never reached: {COVERAGE.missed()}"
