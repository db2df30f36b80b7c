#!/usr/bin/env python3
"""The FPGA flow end to end on small configurations (m = 2 of each
architecture): a real synthesis, place and route, and a report with every
field the benchmark and the docs rely on. Run by `make test-fpga` (part of
`make test`) as `python3 scripts/fpga/test_flow.py <seed-m2-dir> <stream-m2-dir>`."""
import contextlib
import io
import json
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # the flow's package, for the tests that need no tools
from fpgaflow import design, ecp5, names, report, tools  # noqa: E402

VERILOG_DIRS: dict[str, Path] = {}
FLOWS: dict[str, tuple[subprocess.Popen, Path, Path, Path]] = {}  # arch: (its run, report, work dir, output)
TMP = tempfile.TemporaryDirectory()


# The Xilinx estimate synthesises whatever Verilog it is given, so one flow
# tests it: the seed's, whose place and route is the shorter of the two.
XILINX_ESTIMATE = {"stream": False, "seed": True}


def setUpModule():
    """Both architectures' flows side by side (each is single-threaded)."""
    for arch in XILINX_ESTIMATE:
        out = Path(TMP.name) / f"{arch}-m2.json"
        work = HERE.parent.parent / "build" / f"fpga-test-work-{arch}"
        output = Path(TMP.name) / f"{arch}-m2.log"
        with open(output, "w") as f:
            run = subprocess.Popen([sys.executable, str(HERE / "flow.py"), "--verilog-dir", str(VERILOG_DIRS[arch]),
                                    "--m", "2", "--out", str(out), "--work-dir", str(work), "--no-breakdown",
                                    *([] if XILINX_ESTIMATE[arch] else ["--no-xilinx"])],
                                   stdout=f, stderr=subprocess.STDOUT)
        FLOWS[arch] = (run, out, work, output)


def load_tests(loader, standard_tests, pattern):
    """The seed's flow first, then the tests of a few seconds each, which run
    beside the stream's longer place and route, then the stream's flow."""
    first, last = ["FlowOnSmallConfiguration"], ["FlowOnSmallStreamConfiguration"]
    cases = [c for c in globals().values() if isinstance(c, type) and issubclass(c, unittest.TestCase)]
    middle = sorted(c.__name__ for c in cases if c.__name__ not in first + last)
    suite = unittest.TestSuite()
    for name in first + middle + last:
        suite.addTests(loader.loadTestsFromTestCase(globals()[name]))
    return suite


def tearDownModule():
    for run, _, _, _ in FLOWS.values():
        if run.poll() is None:
            run.kill()
        run.wait()
    TMP.cleanup()


class FlowOnSmallConfiguration(unittest.TestCase):
    """The seed's architecture at m = 2: 6m striped memories."""
    ARCH = "seed"
    MEMORY_INSTANCES = 12  # 6 coordinates x 2 lanes, each 256 x 32 bits

    @classmethod
    def setUpClass(cls):
        run, cls.out, cls.work, output = FLOWS[cls.ARCH]
        cls.returncode = run.wait()
        cls.output = output.read_text()

    def report(self):
        self.assertEqual(self.returncode, 0, self.output[-6000:])
        return json.loads(self.out.read_text())

    def test_places_and_routes_and_reports_a_measured_fmax(self):
        r = self.report()
        self.assertEqual(r["status"], "ok")
        self.assertTrue(r["fits"])
        self.assertEqual(r["m"], 2)
        self.assertEqual(r["arch"], self.ARCH)
        self.assertEqual(r["part"]["ecp5_part"], ecp5.PARTS[names.DEFAULT_PART].facts())
        # The commit of the design it measured (this test runs in a clone).
        self.assertRegex(r["source_revision"] or "", r"^[0-9a-f]{7,40}(-dirty)?$")
        e = r["ecp5"]
        self.assertGreater(e["fmax_mhz"], 10)
        self.assertLess(e["fmax_mhz"], 1000)
        # m x Fmax; the report rounds Fmax to 0.01 MHz, the rate uses nextpnr's full value.
        self.assertLessEqual(abs(e["pair_tests_per_second"] - 2 * e["fmax_mhz"] * 1e6), 2 * 0.005e6 + 1)

    def test_counts_resources_and_keeps_the_memories_in_block_ram(self):
        r = self.report()
        e = r["ecp5"]
        self.assertGreater(e["luts"], 100)
        self.assertGreater(e["ffs"], 100)
        # At least one DP16KD a memory.
        self.assertGreaterEqual(e["bram_dp16kd"], self.MEMORY_INSTANCES)
        self.assertTrue(r["memories"]["memories_in_bram"])
        self.assertEqual(r["memories"]["instances"], self.MEMORY_INSTANCES)

    def test_adds_a_xilinx_estimate_unless_told_not_to(self):
        x = self.report()["xilinx_estimate"]
        if not XILINX_ESTIMATE[self.ARCH]:
            self.assertIsNone(x)
            return
        self.assertGreater(x["luts"], 100)
        self.assertGreater(x["bram_ramb18e1"] + 2 * x["bram_ramb36e1"], 0)


class FlowOnSmallStreamConfiguration(FlowOnSmallConfiguration):
    """The stream architecture at m = 2, the FPGA targets' default: one memory
    of six keys a row, and the lanes' enable copies (`*_replica*`), which the
    flow must keep from being merged back into one register."""
    ARCH = "stream"
    MEMORY_INSTANCES = 1

    def test_keeps_every_lane_enable_copy(self):
        self.report()
        netlist = json.loads((self.work / "ecp5.json").read_text())
        nets = {name: tuple(net["bits"]) for mod in netlist["modules"].values()
                for name, net in mod.get("netnames", {}).items()}

        def bits(copy: str):
            found = [b for name, b in nets.items() if name.endswith(copy)]
            self.assertTrue(found, f"no net {copy} in the synthesised netlist")
            return found[0]
        # Lanes 0 and 1 share a group register, so their copies have the same
        # input: merged (opt_merge), their names would be aliases of one net.
        for enable in ("windowWrite", "aLoad", "headCopy", "headShift", "aNextWrite"):
            self.assertNotEqual(bits(f"{enable}_replica0"), bits(f"{enable}_replica1"), enable)


class PartsToPlaceOn(unittest.TestCase):
    """Each ECP5 part the flow offers is one nextpnr-ecp5 places on as described
    (device, package, speed grade), and a report names its part."""
    NETLIST = "module top(input a, output y); assign y = ~a; endmodule\n"

    def nextpnr_accepts(self, args: list[str]) -> subprocess.CompletedProcess:
        with tempfile.TemporaryDirectory() as d:
            work = Path(d)
            (work / "top.v").write_text(self.NETLIST)
            bins = tools.ensure_venv(tools.REPO / ".venv")
            synth = subprocess.run([str(bins["yosys"]), "-q", "-p", "synth_ecp5 -top top -json top.json", "top.v"],
                                   cwd=work, capture_output=True, text=True)
            self.assertEqual(synth.returncode, 0, synth.stderr[-2000:])
            return subprocess.run([str(bins["nextpnr"]), *args, "--json", "top.json", "--lpf-allow-unconstrained",
                                   "--report", "report.json", "--quiet"], cwd=work, capture_output=True, text=True)

    def test_nextpnr_places_on_each_part_as_described(self):
        self.assertEqual(ecp5.PARTS[names.DEFAULT_PART].name, "LFE5U-85F")
        self.assertEqual(ecp5.PARTS["lfe5um5g-85f"].speed, 8)
        for part in ecp5.PARTS.values():
            run = self.nextpnr_accepts(part.nextpnr_args())
            self.assertEqual(run.returncode, 0, (part, run.stdout[-2000:], run.stderr[-2000:]))
        # A speed grade nextpnr-ecp5 does not time the 5G part at is refused: the check above can fail.
        wrong = ecp5.Part("x", "LFE5UM5G-85F", "--um5g-85k", "CABGA381", 6)
        self.assertNotEqual(self.nextpnr_accepts(wrong.nextpnr_args()).returncode, 0)

    def test_names_a_report_by_its_part_only_when_not_the_default(self):
        self.assertEqual(names.design_name("stream", 64), "stream-m64")
        self.assertEqual(names.design_name("stream", 64, part=names.DEFAULT_PART), "stream-m64")
        self.assertEqual(names.design_name("stream", 64, 16, part="lfe5um5g-85f"), "stream-m64-k16-lfe5um5g-85f")

    def test_refuses_a_part_it_does_not_know(self):
        with tempfile.TemporaryDirectory() as empty:
            run = subprocess.run([sys.executable, str(HERE / "flow.py"), "--verilog-dir", empty, "--part", "lfe5u-45f"],
                                 capture_output=True, text=True)
            self.assertEqual(run.returncode, 2)
            self.assertIn("--part", run.stderr)


class BinningDeviceParameters(unittest.TestCase):
    """The binning device's parameter file (EmitBinning's words: lanes, box_capacity) read in the
    flow's words, its names, and its group memories' check."""
    PARAMS = {"arch": "binning", "groups": 32, "lanes_per_group": 2, "lanes": 64, "key_width": 12,
              "box_capacity": 8192, "memory_style": "inferred", "top": "BinningCore",
              "memory_module": "mem_1024x71", "memory_count": 64, "dp16kd_estimate": 160}

    def read(self, **changes) -> dict:
        with tempfile.TemporaryDirectory() as d:
            (Path(d) / design.PARAMS_FILE).write_text(json.dumps(dict(self.PARAMS, **changes)))
            return design.read_params(Path(d))

    def test_reads_lanes_as_m_and_the_box_capacity_as_capacity(self):
        p = self.read()
        self.assertEqual((p["m"], p["capacity"], p["top"]), (64, 8192, "BinningCore"))
        with self.assertRaises(tools.FlowError):  # --m checks the lanes
            with tempfile.TemporaryDirectory() as d:
                (Path(d) / design.PARAMS_FILE).write_text(json.dumps(self.PARAMS))
                design.read_params(Path(d), m=32)
        stream = {"arch": "stream", "m": 8, "capacity": 512}
        self.assertIs(names.flow_params(stream), stream)

    def test_names_it_by_lanes_and_only_what_differs_from_its_defaults(self):
        self.assertEqual(names.params_name(self.read()), "binning-m64")
        self.assertEqual(names.params_name(self.read(), "lfe5um5g-85f"), "binning-m64-lfe5um5g-85f")
        self.assertEqual(names.params_name(self.read(lanes=128, box_capacity=4096, key_width=16)),
                         "binning-m128-c4096-k16")
        self.assertEqual(names.design_name("binning", 64), "binning-m64")
        # Its default key width is its own: the other architectures' names are unchanged.
        self.assertEqual(names.design_name("stream", 64, 12), "stream-m64-k12")
        self.assertEqual(names.design_name("stream", 64), "stream-m64")

    def test_counts_the_group_memories_in_block_ram(self):
        core = type("Core", (), {"params": dict(self.PARAMS), "memory_module": "mem_1024x71"})()
        log = "".join(f"mapping memory FpgaTop.core.g{i}.mem_ext.Memory via $__ECP5_PDPW16KD_\n" for i in range(64))
        tables = "".join(f"mapping memory FpgaTop.core.t{i}.mem_ext.Memory via $__TRELLIS_DPR16X4_\n" for i in range(32))
        cells = {"DP16KD": 160, "TRELLIS_DPR16X4": 768}
        ok = ecp5.memories(core, cells, log + tables, [])
        self.assertTrue(ok["memories_in_bram"], ok)
        self.assertEqual((ok["dp16kd"], ok["dp16kd_estimate"], ok["lut_ram_trellis_dpr16x4"]), (160, 160, 768))
        one_in_lut_ram = log.replace("PDPW16KD", "TRELLIS_DPR16X4", 1)
        self.assertFalse(ecp5.memories(core, cells, one_in_lut_ram + tables, [])["memories_in_bram"])

        # A routed report's summary names the mapping it has (all memories'), not the other architectures' field.
        routed = {"arch": "binning", "m": 64, "capacity": 8192, "part": {"ecp5": "LFE5UM5G-85F"}, "status": "ok",
                  "ecp5": {"luts": 1, "ffs": 1, "bram_dp16kd": 160, "fmax_mhz": 100.0, "clock_constraint_mhz": 200,
                           "timing_met": False, "pair_tests_per_second": 6.4e9},
                  "memories": ok, "runtime_s": {}}
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            report.print_summary(routed)
        self.assertIn("memories in block RAM: True ({'$__ECP5_PDPW16KD_': 64", printed.getvalue())


class FlowRefusesBadInput(unittest.TestCase):
    def test_fails_loudly_on_bad_input(self):
        with tempfile.TemporaryDirectory() as empty:
            run = subprocess.run([sys.executable, str(HERE / "flow.py"), "--verilog-dir", empty, "--m", "2",
                                  "--out", str(Path(empty) / "r.json")], capture_output=True, text=True)
            self.assertNotEqual(run.returncode, 0)
            self.assertFalse((Path(empty) / "r.json").exists())


class MemoryWithoutCollisionBypass(unittest.TestCase):
    """Each emitted memory, followed by its first output register (every engine
    has one), maps to block RAM alone: the vendors' "no read-during-write check"
    attributes (src/bpaccel/NoCollisionMemories.scala), each of which Yosys reads,
    spare it the bypass Yosys otherwise builds for a read meeting a write at the same row."""
    ATTRIBUTE = '(* ramstyle = "no_rw_check", syn_ramstyle = "no_rw_check", rw_addr_collision = "no" *) '
    WRAPPER = ("module top(input clock, input [{a}:0] ra, input ren, input [{a}:0] wa, input wen,\n"
               "           input [{w}:0] wd, output reg [{w}:0] q);\n"
               "  wire [{w}:0] d;\n"
               "  {mem} m(.R0_addr(ra), .R0_en(ren), .clock(clock), .R0_data(d), .W0_addr(wa), .W0_en(wen), "
               ".W0_data(wd));\n"
               "  always @(posedge clock) q <= d;\n"
               "endmodule\n")

    def cells(self, memory_text: str, name: str, rows: int, width: int) -> dict:
        with tempfile.TemporaryDirectory() as d:
            work = Path(d)
            (work / "mem.sv").write_text(memory_text)
            (work / "top.v").write_text(self.WRAPPER.format(a=(rows - 1).bit_length() - 1, w=width - 1, mem=name))
            yosys = tools.ensure_venv(tools.REPO / ".venv")["yosys"]
            run = subprocess.run([str(yosys), "-q", "-p", "read_verilog -sv mem.sv top.v; synth_ecp5 -top top; "
                                  "tee -q -o stat.json stat -json"], cwd=work, capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, run.stderr[-2000:])
            return json.loads((work / "stat.json").read_text())["modules"]["\\top"]["num_cells_by_type"]

    def test_maps_each_memory_to_a_dp16kd_without_logic(self):
        memories = sorted(VERILOG_DIRS["seed"].glob("mem_*.sv"))
        self.assertTrue(memories)
        path = memories[0]
        name = path.stem
        rows, width = (int(x) for x in name.removeprefix("mem_").split("x"))
        text = path.read_text()
        self.assertIn(self.ATTRIBUTE, text)
        for attribute in (self.ATTRIBUTE, '(* ramstyle = "no_rw_check" *) ', '(* syn_ramstyle = "no_rw_check" *) '):
            cells = self.cells(text.replace(self.ATTRIBUTE, attribute), name, rows, width)
            self.assertGreaterEqual(cells.get("DP16KD", 0), 1, (attribute, cells))
            self.assertNotIn("LUT4", cells, (attribute, cells))
        # Without the attribute the bypass comes back: the check above can fail.
        bypassed = self.cells(text.replace(self.ATTRIBUTE, ""), name, rows, width)
        self.assertGreater(bypassed.get("LUT4", 0), width // 2, bypassed)


class RegisteredMemorySubstitution(unittest.TestCase):
    """The ECP5 run builds the generator's RegisteredReadMemory modules from DP16KD
    (memory style ecp5-outreg), and only when their ports are the generator's."""
    PORTS = {"clock": 1, "reset": 1, "io_writeEnable": 1, "io_writeRow": 9, "io_writeData": 20,
             "io_readEnable": 1, "io_readRow": 9, "io_readData": 20}

    def test_replaces_the_module_by_dp16kd_with_the_output_register(self):
        source, facts = ecp5.registered_memory("RegisteredReadMemory_300x20", 300, 20, dict(self.PORTS))
        self.assertEqual(facts, {"module": "RegisteredReadMemory_300x20", "rows": 300, "width": 20, "dp16kd": 2})
        self.assertIn("module RegisteredReadMemory_300x20(", source)
        self.assertIn(".ROWS(300), .WIDTH(20), .ROW_BITS(9)", source)
        self.assertIn('parameter REGMODE = "OUTREG"', ecp5.REGISTERED_MEMORY_SOURCE.read_text())

    def test_refuses_ports_that_are_not_the_generators(self):
        renamed = {("io_readEn" if k == "io_readEnable" else k): v for k, v in self.PORTS.items()}
        for wrong in (dict(self.PORTS, io_readRow=10), renamed):
            with self.assertRaises(tools.FlowError):
                ecp5.registered_memory("RegisteredReadMemory_300x20", 300, 20, wrong)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit("usage: test_flow.py <seed m=2 verilog dir> <stream m=2 verilog dir> (each with filelist.f)")
    VERILOG_DIRS["seed"] = Path(sys.argv.pop(1)).resolve()
    VERILOG_DIRS["stream"] = Path(sys.argv.pop(1)).resolve()
    unittest.main(verbosity=2)
