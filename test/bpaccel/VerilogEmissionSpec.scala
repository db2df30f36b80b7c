package bpaccel

import java.nio.file.{Files, Path}

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import scala.jdk.CollectionConverters._
import scala.sys.process._

/** What FPGA flows get: lint-clean SystemVerilog whose buffers are memories. */
class VerilogEmissionSpec extends AnyFlatSpec with Matchers {

  private def emitted(m: Int, arch: Arch = Arch.Seed, capacity: Option[Int] = None): (AccelParams, Path) = {
    val p   = AccelParams(m = m, capacity = capacity.getOrElse(AccelParams.defaultCapacity(m)), arch = arch)
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

  for (m <- Seq(1, 3, 16))
    it should s"pass verilator --lint-only -Wall without a warning for the stream architecture, m=$m" in {
      lint(emitted(m, Arch.Stream, capacity = Some(1000))._2)
    }

  it should "give the stream architecture one memory of six keys a row, whatever m" in {
    for (m <- Seq(2, 16)) withClue(s"m=$m: ") {
      val (p, dir) = emitted(m, Arch.Stream, capacity = Some(2048))
      val memories = svFiles(dir).filter(_.startsWith("mem_"))
      memories shouldBe Seq(s"mem_2048x${6 * p.keyWidth}.sv")
      read(dir, memories.head) should include(s"reg [${6 * p.keyWidth - 1}:0] Memory[0:2047];")
      read(dir, "bpaccel_params.h") should include("#define BPACCEL_ARCH \"stream\"\n")
      svFiles(dir) should not contain "Rotator.sv"
    }
  }
}
