package bpaccel

import java.nio.file.{Files, Path}

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import scala.jdk.CollectionConverters._
import scala.util.matching.Regex
import scala.sys.process._

/** What FPGA flows get: lint-clean SystemVerilog whose buffers are memories. */
class VerilogEmissionSpec extends AnyFlatSpec with Matchers {

  private def emitted(m: Int, arch: Arch = Arch.Seed, capacity: Option[Int] = None): (AccelParams, Path) = {
    val p   = AccelParams(m = m, capacity = capacity.getOrElse(arch.defaultCapacity(m)), arch = arch)
    val dir = Files.createTempDirectory(s"bpaccel-${arch.name}-m$m-")
    EmitVerilog.emit(p, dir)
    (p, dir)
  }

  private def read(dir: Path, file: String): String = Files.readString(dir.resolve(file))

  behavior of "The emitted Verilog"

  private def lint(dir: Path): Unit = {
      val log      = new StringBuilder
      val exit = Process(
        Seq("verilator", "--lint-only", "-Wall", EmitVerilog.lintWaivers, "-F", "filelist.f", "--top-module", "BroadPhaseAccel"),
        dir.toFile
      ).!(ProcessLogger(l => log.append(l).append('\n'), l => log.append(l).append('\n')))
      withClue(log.toString) {
        exit shouldBe 0
        log.toString.trim shouldBe empty
      }
  }

  private def svFiles(dir: Path): Seq[String] =
    Files.list(dir).iterator().asScala.map(_.getFileName.toString).filter(_.endsWith(".sv")).toSeq

  for (m <- Seq(1, 3, 16, 64)) {
    it should s"pass verilator --lint-only -Wall without a warning for m=$m" in {
      lint(emitted(m)._2)
    }

    it should s"build each coordinate buffer from memories, not registers, for m=$m" in {
      val (p, dir) = emitted(m)
      val memModule = s"mem_${p.depth}x${p.keyWidth}"
      // The memory module declares one array of depth x keyWidth ...
      read(dir, s"$memModule.sv") should include(s"reg [${p.keyWidth - 1}:0] Memory[0:${p.depth - 1}];")
      // ... and the buffers instantiate it six times per lane: 6m dual-port memories.
      val instances = s"(?m)^\\s*$memModule\\s+\\w+\\s*\\(".r.findAllIn(read(dir, "CoordBuffer.sv")).length
      instances shouldBe 6 * m
      // No other file holds a storage array of that size.
      for (f <- svFiles(dir) if f != s"$memModule.sv")
        withClue(s"$f: ") { read(dir, f) should not include s"[0:${p.depth - 1}]" }
      // The C header agrees with the parameters.
      read(dir, "bpaccel_params.h") should include(s"#define BPACCEL_M $m\n")
    }
  }

  /** The `input`/`output` declarations of `module`'s port list, as (direction, name). */
  private def ports(text: String): Seq[(String, String)] = {
    val list = "(?s)module\\s+\\w+\\s*\\((.*?)\\);".r.findFirstMatchIn(text).get.group(1)
    "(?m)^\\s*(input|output)\\s*(?:\\[[^\\]]+\\])?\\s*(\\w+)".r.findAllMatchIn(list).map(x => (x.group(1), x.group(2))).toSeq
  }

  it should "give each seed memory one clock port, one read port and one write port" in {
    val (p, dir) = emitted(4)
    val memModule = s"mem_${p.depth}x${p.keyWidth}"
    val declared  = ports(read(dir, s"$memModule.sv"))
    declared.map(_._2).filter(_.contains("clk")) shouldBe empty
    declared should contain(("input", SingleClockMemories.clockPort))
    declared.map(_._2).filter(_.endsWith("_addr")).sorted shouldBe Seq("R0_addr", "W0_addr")
    read(dir, "CoordBuffer.sv") should not include "_clk"
  }

  it should "give each memory a shape that Xilinx synthesis maps to block RAM out of context" in {
    // The memory module alone, as a vendor flow synthesising it out of context would see it:
    // with one clock the read-address register merges into the block RAM; with a clock per
    // port (firtool's own output) Yosys 0.23 falls back to LUT RAM.
    val (p, dir) = emitted(2)
    val memModule = s"mem_${p.depth}x${p.keyWidth}"
    val log = new StringBuilder
    val exit = Process(
      Seq("yosys", "-p", s"read_verilog -sv $memModule.sv; synth_xilinx -family xc7 -top $memModule; stat"),
      dir.toFile
    ).!(ProcessLogger(l => log.append(l).append('\n'), l => log.append(l).append('\n')))
    withClue(log.toString.takeRight(3000)) {
      exit shouldBe 0
      "(?m)^\\s+RAMB18E1\\s+1$".r.findFirstIn(log.toString) shouldBe defined
      "(?m)^\\s+RAM(32M|64M|128X1D)\\s+\\d+$".r.findFirstIn(log.toString) shouldBe empty
    }
  }

  for (arch <- Arch.all)
    it should s"mark every memory array of the ${arch.name} architecture as never read and written at one row at once" in {
      val (_, dir) = emitted(3, arch)
      val memories = svFiles(dir).filter(_.startsWith("mem_"))
      memories should not be empty
      for (f <- memories)
        withClue(s"$f: ") {
          s"(?m)^\\s*${Regex.quote(NoCollisionMemories.attribute)} reg \\[[^\\]]+\\] Memory\\[".r.findAllIn(read(dir, f)).length shouldBe 1
        }
    }

  /** The write-port connections of every coordinate memory instance in `text` (not the
    * queues' small RAMs): (port, what it is connected to).
    */
  private def memoryWritePorts(text: String): Seq[(String, String)] =
    s"""(?s)\\b(?:mem_|${RegisteredReadMemory.namePrefix})\\w+\\s+\\w+\\s*\\((.*?)\\n\\s*\\);""".r
      .findAllMatchIn(text).toSeq.flatMap(instance =>
        """\.(W0_en|W0_addr|W0_data|io_writeEnable|io_writeRow|io_writeData)\s*\(([^()]*)\)""".r
          .findAllMatchIn(instance.group(1)).map(x => (x.group(1), x.group(2).trim)))

  /** Names declared as `reg` in `text`. */
  private def registerNames(text: String): Set[String] =
    """(?m)^\s*reg\s*(?:\[[^\]]+\])?\s*(\w+)\s*;""".r.findAllMatchIn(text).map(_.group(1)).toSet

  // The load handshake must not reach the block RAMs' write ports through
  // logic: a registered write port took it off seed m = 8's and stream
  // m = 32's critical paths (docs/fpga.md).
  for (arch <- Arch.all; m <- Seq(1, 3, 8))
    it should s"drive every memory write port of the ${arch.name} architecture straight from registers, m=$m" in {
      val (_, dir) = emitted(m, arch, capacity = Some(24 * m))
      val users = svFiles(dir).filterNot(_.startsWith("mem_")).filterNot(_.startsWith(RegisteredReadMemory.namePrefix))
      val ports = users.flatMap(f => memoryWritePorts(read(dir, f)).map(f -> _))
      ports.map(_._2._1).toSet should contain atLeastOneOf ("W0_en", "io_writeEnable")
      for ((f, (port, signal)) <- ports) withClue(s"$f: .$port($signal): ") {
        // A bare register or a concatenation of registers: no gate between them and the port.
        val names = """[A-Za-z_]\w*""".r.findAllIn(signal).toSeq
        signal should fullyMatch regex """\{?\s*[A-Za-z_]\w*(\s*,\s*[A-Za-z_]\w*)*\s*\}?"""
        registerNames(read(dir, f)) should contain allElementsOf names
      }
    }

  it should "refuse to mark a memory module whose array it does not recognise" in {
    val (p, dir) = emitted(1)
    val mem = dir.resolve(s"mem_${p.depth}x${p.keyWidth}.sv")
    Files.writeString(mem, read(dir, mem.getFileName.toString).replace(s"${NoCollisionMemories.attribute} reg", "reg").replace("Memory[", "Storage["))
    val e = the[IllegalStateException] thrownBy NoCollisionMemories.rewrite(dir)
    e.getMessage should include("expected one 'reg [..] Memory[..];', found 0")
  }

  it should "refuse to merge the clocks of a memory whose ports are clocked differently" in {
    val (p, dir) = emitted(1)
    val coords = dir.resolve("CoordBuffer.sv")
    // Undo the rewrite of one instance and clock its write port from another signal.
    val broken = read(dir, "CoordBuffer.sv")
      .replaceFirst("\\.clock\\s*\\(clock\\)", ".R0_clk (clock),\n    .W0_clk (io_readEnable)")
    Files.writeString(coords, broken)
    val mem = dir.resolve(s"mem_${p.depth}x${p.keyWidth}.sv")
    Files.writeString(mem, read(dir, mem.getFileName.toString)
      .replaceFirst(s"input\\s+${SingleClockMemories.clockPort}", "input R0_clk,\n  input W0_clk"))
    val e = the[IllegalStateException] thrownBy SingleClockMemories.rewrite(dir)
    e.getMessage should include("clocks its ports differently")
  }

  // A capacity of 2^k (the host's and the FPGA flow's) makes counts one bit wider than indices.
  for ((m, capacity) <- Seq(1 -> 1000, 3 -> 1000, 16 -> 1000, 8 -> 2048, 64 -> 2048))
    it should s"pass verilator --lint-only -Wall without a warning for the stream architecture, m=$m, capacity $capacity" in {
      lint(emitted(m, Arch.Stream, capacity = Some(capacity))._2)
    }

  it should "give the stream architecture one memory of six keys a row, two banks of the capacity, whatever m" in {
    for (m <- Seq(2, 16)) withClue(s"m=$m: ") {
      val (p, dir) = emitted(m, Arch.Stream, capacity = Some(2048))
      val memories = svFiles(dir).filter(_.startsWith("mem_"))
      memories shouldBe Seq(s"mem_4096x${6 * p.keyWidth}.sv")
      read(dir, memories.head) should include(s"reg [${6 * p.keyWidth - 1}:0] Memory[0:4095];")
      read(dir, "bpaccel_params.h") should include("#define BPACCEL_ARCH \"stream\"\n")
      svFiles(dir) should not contain "Rotator.sv"
    }
  }

  // firtool 1.62.1 now and then put a lane's assignment under another
  // lane's enable copy (docs/verification.md); every emission checks it.
  for (m <- Seq(3, 16))
    it should s"put every lane register of the stream engine under its own lane's enable copies, m=$m" in {
      val (p, dir) = emitted(m, Arch.Stream, capacity = Some(24 * m))
      val text     = read(dir, LaneEnables.file)
      LaneEnables.mismatches(text) shouldBe empty
      LaneEnables.unguarded(text, m) shouldBe empty
      // What the miscompile looked like: lane 2's copy from the head chain under lane 1's head shift.
      val broken = text.replaceFirst("if \\(windowWrite_replica2\\)(\\s+window_2_box <=)", "if (headShift_replica1)$1")
      broken should not equal text
      LaneEnables.mismatches(broken) shouldBe Seq("window_2_box <=" -> "headShift_replica1")
      Files.writeString(dir.resolve(LaneEnables.file), broken)
      val e = the[IllegalStateException] thrownBy LaneEnables.check(p, dir)
      e.getMessage should include("assigns 'window_2_box <=' under 'headShift_replica1', another lane's enable")
      // A lane whose enables were dropped altogether.
      LaneEnables.unguarded(text.replace("if (aLoad_replica1)", "if (1'h1)"), m) shouldBe Seq("a_1_box")
    }
}
