package bpaccel.shell

import java.nio.file.{Files, Path, Paths}
import java.util.Comparator

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import scala.sys.process._

import bpaccel.{AccelParams, Arch}

/** The emitted shell, as tools see it: lint, no combinational path between
  * ports, the cocotb testbench on Icarus, the register map through PeakRDL,
  * the FuseSoC core's targets. Each configuration is emitted once.
  */
class ShellSpec extends AnyFlatSpec with Matchers {
  private val venv = Paths.get("build/shell-venv/bin").toAbsolutePath
  private val smokeTestbench = Paths.get("test/fusesoc/bpaccel_shell_smoke_tb.sv")

  /** Configurations that between them take every path of the shell: both
    * architectures, both clockings, key slots of 16 and 32 bits (with and
    * without KEY_TOO_WIDE), one and two mask words, 64 to 512 bits of stream.
    */
  private val configurations = Seq(
    "stream-m8-w128-dual" -> ShellParams(),
    "seed-m4-w64-single-k12" ->
      ShellParams(AccelParams(m = 4, capacity = 32, keyWidth = 12, arch = Arch.Seed), streamBits = 64, dualClock = false),
    "stream-m33-w512-dual-k16" ->
      ShellParams(AccelParams(m = 33, capacity = 40, keyWidth = 16, arch = Arch.Stream, batchCells = 4), streamBits = 512)
  )

  /** Emits `p` into a fresh build/shell-test/`name`. */
  private def emitFresh(name: String, p: ShellParams, testbench: Option[Path]): Path = {
    val dir = Paths.get("build/shell-test", name).toAbsolutePath
    if (Files.exists(dir)) Files.walk(dir).sorted(Comparator.reverseOrder[Path]()).forEach(f => Files.delete(f))
    EmitShell.emit(p, dir, testbench)
    dir
  }

  private val emitted: Map[String, Path] = configurations.map { case (name, p) => name -> emitFresh(name, p, Some(smokeTestbench)) }.toMap

  private def run(command: Seq[String], dir: Path): (Int, String) = {
    val log  = new StringBuilder
    val exit = Process(command, dir.toFile).!(ProcessLogger(l => log.append(l).append('\n'), l => log.append(l).append('\n')))
    (exit, log.toString)
  }

  private def lintClean(dir: Path): Unit = {
    val (exit, log) = run(Seq("verilator", "--lint-only", "-Wall", "lint_waivers.vlt", "-F", "filelist.f", "--top-module", EmitShell.top), dir)
    withClue(log) { exit shouldBe 0; log.trim shouldBe empty }
  }

  /** Input -> output port pairs joined by logic alone in `top` (comb_paths.py: Yosys flattens it to
    * gates; `blackBoxes` count as paths from each of their inputs to each of their outputs).
    */
  private def combinationalPaths(dir: Path, top: String, blackBoxes: Seq[String] = Nil): Seq[String] = {
    val (exit, out) = run(Seq("python3", Paths.get("test/bpaccel/shell/comb_paths.py").toAbsolutePath.toString, dir.toString, top) ++ blackBoxes, dir)
    val found = out.linesIterator.filter(_.startsWith("combinational path")).toSeq
    withClue(out) { exit shouldBe (if (found.isEmpty) 0 else 1) }
    found
  }

  for ((name, _) <- configurations) {
    val dir = emitted(name)
    s"The shell $name" should "pass verilator --lint-only -Wall without a warning" in lintClean(dir)

    it should "have no combinational path from an input port to an output port" in {
      combinationalPaths(dir, EmitShell.top, blackBoxes = Seq("BroadPhaseAccel")) shouldBe empty
    }

    it should "pass the cocotb testbench on Icarus" in {
      val (exit, log) = run(Seq(venv.resolve("python").toString, Paths.get("test/cocotb/run.py").toAbsolutePath.toString, dir.toString), dir)
      val summary = log.linesIterator.filter(l => l.contains("FAIL") || l.startsWith("cocotb on")).mkString("\n")
      info(log.linesIterator.filter(_.startsWith("cocotb on")).mkString)
      withClue(summary + "\n" + log.takeRight(4000)) { exit shouldBe 0 }
    }
  }

  /** The binning core's shell on two clocks (FrameShellSpec simulates it on one): the tools' view of it. */
  private val binningShell = emitFresh("binning-g8-w128-dual", ShellParams(ShellConfigs.binningG8), None)

  "The binning shell" should "pass verilator --lint-only -Wall without a warning" in lintClean(binningShell)

  it should "have no combinational path from an input port to an output port" in {
    combinationalPaths(binningShell, EmitShell.top, blackBoxes = Seq("BinningCore")) shouldBe empty
  }

  "The combinational path check" should "find the bare core's path from cells.valid to load.ready" in {
    // The check itself must be able to fail: the core without its shell has such a path.
    combinationalPaths(emitted(configurations.head._1), "BroadPhaseAccel") should contain("combinational path: io_cells_valid -> io_load_ready")
  }

  "The register map" should "compile with PeakRDL to the offsets, masks and reset values it describes" in {
    val (name, p) = configurations.head
    val dir = emitted(name)
    val map = ShellRegisters(p)
    val (dumpExit, dump) = run(Seq(venv.resolve("peakrdl").toString, "dump", "bpaccel_shell.rdl"), dir)
    withClue(dump) { dumpExit shouldBe 0 }
    val offsets = "(?m)^0x([0-9a-f]+)-0x[0-9a-f]+: bpaccel_shell\\.(\\w+)$".r.findAllMatchIn(dump).map(m => m.group(2) -> Integer.parseInt(m.group(1), 16)).toMap
    offsets shouldBe map.registers.map(r => r.name -> r.offset).toMap
    val header = dir.resolve("peakrdl.h")
    val (cExit, cLog) = run(Seq(venv.resolve("peakrdl").toString, "c-header", "bpaccel_shell.rdl", "-o", header.toString), dir)
    withClue(cLog) { cExit shouldBe 0 }
    val defines = "(?m)^#define BPACCEL_SHELL__(\\w+)__(\\w+)_(bm|reset) (0x[0-9a-f]+)".r.findAllMatchIn(Files.readString(header))
      .map(m => (m.group(1), m.group(2), m.group(3)) -> BigInt(m.group(4).drop(2), 16)).toMap
    for (r <- map.registers; f <- r.fields) withClue(s"${r.name}.${f.name}: ") {
      defines((r.name, f.name, "bm")) shouldBe f.mask
      if (f.constant.isDefined || f.access != Access.ReadOnly) defines((r.name, f.name, "reset")) shouldBe f.resetValue
    }
  }

  it should "be the one docs/registers.md describes" in {
    val p = ShellParams()
    Files.readString(Paths.get("docs/registers.md")) shouldBe RegisterMapEmitters.markdown(ShellRegisters(p), p)
  }

  "The FuseSoC core" should "lint and run its smoke test" in {
    for ((name, _) <- configurations.take(2); target <- Seq("lint", "sim")) withClue(s"$name, $target: ") {
      val work = Files.createTempDirectory("bpaccel-fusesoc-")
      val (exit, log) = run(Seq(venv.resolve("fusesoc").toString, "--cores-root", emitted(name).toString, "run", "--target", target,
        "bpaccel:accel:bpaccel_shell"), work)
      withClue(log) {
        exit shouldBe 0
        if (target == "sim") log should include("PASS: bpaccel shell smoke test")
      }
    }
  }
}
