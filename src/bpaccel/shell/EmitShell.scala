package bpaccel.shell

import java.nio.file.{Files, Path, Paths}

import chisel3.stage.ChiselGeneratorAnnotation
import circt.stage.{ChiselStage, FirtoolOption}

import bpaccel.{AccelParams, Arch, EmitVerilog, Emitter, MemoryStyle, SingleClockMemories}
import bpaccel.binning.{BinningOptions, BinningParams, EmitBinning}

/** Emits the shell of one configuration: its SystemVerilog (one file per
  * module, filelist.f), the core's bpaccel_params.h, the shell's
  * bpaccel_shell.h (registers and protocol), bpaccel_shell.rdl (SystemRDL)
  * and registers.md.
  *
  * Usage: EmitShell --arch stream --m 8 --capacity 64 --stream-bits 128 --target-dir build/shell
  *        EmitShell --arch binning --group-bits 1,1,1 --lanes-per-group 2 --capacity 1024 --target-dir build/shell
  * (the binning core also writes bpaccel_binning_params.h and bpaccel_params.json).
  */
object EmitShell {
  val top = "BpaccelShell"

  /** Emits into `targetDir`; with a smoke testbench, copies it there for the FuseSoC core's `sim` target. */
  def emit(p: ShellParams, targetDir: Path, smokeTestbench: Option[Path] = None): Path = {
    Files.createDirectories(targetDir)
    (new ChiselStage).execute(
      Array("--target", "systemverilog", "--split-verilog", "--target-dir", targetDir.toString),
      Seq(ChiselGeneratorAnnotation(() => new BpaccelShell(p))) ++ firtoolOptions.map(FirtoolOption(_))
    )
    p.core match {
      case ShellCoreParams.Cells(c)   => EmitVerilog.finishCore(c, targetDir)
      case ShellCoreParams.Binning(b) => EmitBinning.finishCore(b, targetDir)
    }
    val map = ShellRegisters(p)
    Files.writeString(targetDir.resolve("bpaccel_shell.h"), ShellHeader(p))
    Files.writeString(targetDir.resolve("bpaccel_shell.rdl"), RegisterMapEmitters.systemRdl(map))
    Files.writeString(targetDir.resolve("registers.md"), RegisterMapEmitters.markdown(map, p))
    Files.writeString(targetDir.resolve(EmitVerilog.lintWaivers), lintWaivers)
    smokeTestbench.foreach(tb => Files.copy(tb, targetDir.resolve(tb.getFileName), java.nio.file.StandardCopyOption.REPLACE_EXISTING))
    Files.writeString(targetDir.resolve(FuseSocCore.fileName), FuseSocCore(p, SingleClockMemories.listedFiles(targetDir), smokeTestbench))
    targetDir.resolve("filelist.f")
  }

  /** The core's firtool options, with `always @(*)` for `always_comb`: Icarus
    * Verilog 11 (the cocotb testbench's simulator) does not take always_comb
    * blocks that select constant bits.
    */
  val firtoolOptions: Seq[String] = EmitVerilog.firtoolOptions.toSeq.map(o =>
    if (o.startsWith("--lowering-options=")) s"$o,noAlwaysComb" else o)

  /** Verilator's waivers for `verilator --lint-only -Wall lint_waivers.vlt -F filelist.f`. */
  private val lintWaivers =
    "`verilator_config\n" +
      "// chisel3.util.Queue's memory reads combinationally: firtool's ram module has an unused read clock.\n" +
      "lint_off -rule UNUSEDSIGNAL -file \"*ram_*.sv\" -match \"*R0_clk*\"\n" +
      "// So does the asynchronous FIFOs' storage (its read is on the reader's side, without a clock).\n" +
      "lint_off -rule UNUSEDSIGNAL -file \"*storage_*.sv\" -match \"*R0_clk*\"\n" +
      "// The register bank keeps whole write beats; only the writable fields' bits are used.\n" +
      "lint_off -rule UNUSEDSIGNAL -file \"*AxiLiteRegisterBank.sv\" -match \"*wData*\"\n" +
      "lint_off -rule UNUSEDSIGNAL -file \"*AxiLiteRegisterBank.sv\" -match \"*wStrb*\"\n"

  private case class Options(
    arch: String = Arch.Stream.name,
    m: Int = 8,
    capacity: Option[Int] = None,
    keyWidth: Option[Int] = None,
    batchCells: Int = AccelParams().batchCells,
    memoryStyle: String = MemoryStyle.Inferred.name,
    binning: BinningOptions = BinningOptions(),
    streamBits: Int = ShellParams().streamBits,
    dualClock: Boolean = true,
    fifoDepth: Int = ShellParams().fifoDepth,
    targetDir: Path = Paths.get("build/shell"),
    smokeTestbench: Option[Path] = None
  ) {
    def core: ShellCoreParams = {
      val archs = Arch.all.map(_.name) :+ "binning"
      require(archs.contains(arch), s"arch must be one of ${archs.mkString(", ")}, got arch = $arch")
      if (arch == "binning")
        binning.copy(boxCapacity = capacity, keyWidth = keyWidth, memoryStyle = Some(memoryStyle)).params()
      else
        AccelParams(m = m, capacity = capacity.getOrElse(Arch.fromName(arch).defaultCapacity(m)), keyWidth = keyWidth.getOrElse(32),
          arch = Arch.fromName(arch), batchCells = batchCells, memoryStyle = MemoryStyle.fromName(memoryStyle))
    }
    def params: ShellParams = ShellParams(core, streamBits, dualClock, fifoDepth)
  }

  def main(args: Array[String]): Unit = {
    val parser = new scopt.OptionParser[Options]("EmitShell") {
      head("Emits the bpaccel AXI shell's SystemVerilog, C headers, SystemRDL and register page")
      val b = BinningParams()
      def binning(name: String, doc: String)(set: (BinningOptions, Int) => BinningOptions) =
        opt[Int](name).action((v, o) => o.copy(binning = set(o.binning, v))).text(s"binning: $doc")
      opt[String]("arch").action((v, o) => o.copy(arch = v)).text("core architecture: seed, stream or binning (default stream)")
      opt[Int]("m").action((v, o) => o.copy(m = v)).text("seed, stream: lanes")
      opt[Int]("capacity").action((v, o) => o.copy(capacity = Some(v)))
        .text(s"boxes per cell (seed, stream; default: the architecture's) or per frame (binning; default ${b.boxCapacity})")
      opt[Int]("key-width").action((v, o) => o.copy(keyWidth = Some(v))).text(s"bits per key (at most 32; default 32, binning ${b.keyWidth})")
      opt[Int]("batch-cells").action((v, o) => o.copy(batchCells = v)).text("seed, stream: cell counts the core queues")
      opt[Seq[Int]]("group-bits")(BinningOptions.groupBitsRead).action((v, o) => o.copy(binning = o.binning.copy(groupBits = Some(v))))
        .text(s"binning: ax,ay,az, 2^a lane groups per axis (default ${b.groupBits.mkString(",")})")
      binning("lanes-per-group", s"lanes of each group (default ${b.g})")((q, v) => q.copy(lanesPerGroup = Some(v)))
      binning("cell-bits", s"grid cells per axis at most 2^cell-bits (default ${b.cellBits})")((q, v) => q.copy(cellBits = Some(v)))
      binning("group-capacity", s"entries of each group's memory (default ${b.groupCapacity})")((q, v) => q.copy(groupCapacity = Some(v)))
      binning("intake-boxes", s"boxes the core takes a cycle (default ${b.intakeBoxes})")((q, v) => q.copy(intakeBoxes = Some(v)))
      binning("pairs-per-beat", s"pairs the core sends a cycle (default ${b.pairsPerBeat})")((q, v) => q.copy(pairsPerBeat = Some(v)))
      opt[String]("memory-style").action((v, o) => o.copy(memoryStyle = v)).text("inferred or ecp5-outreg")
      opt[Int]("stream-bits").action((v, o) => o.copy(streamBits = v)).text("TDATA bits: 64, 128, 256 or 512")
      opt[Boolean]("dual-clock").action((v, o) => o.copy(dualClock = v)).text("the core on core_clk (default true)")
      opt[Int]("fifo-depth").action((v, o) => o.copy(fifoDepth = v)).text("beats per stream FIFO")
      opt[String]("target-dir").action((v, o) => o.copy(targetDir = Paths.get(v))).text("output folder")
      opt[String]("smoke-testbench")
        .action((v, o) => o.copy(smokeTestbench = Some(Paths.get(v))))
        .text("copy this testbench beside the Verilog for the FuseSoC core's sim target")
    }
    parser.parse(args, Options()) match {
      case Some(o) =>
        val p = Emitter.parametersOrExit("EmitShell")(o.params)
        println(s"wrote ${emit(p, o.targetDir, o.smokeTestbench)} for ${p.fingerprint}")
      case None => sys.exit(2)
    }
  }
}

/** bpaccel_shell.h: the register map and the protocol's constants, for the host's driver. */
object ShellHeader {
  def apply(p: ShellParams): String = {
    val map = ShellRegisters(p)
    val params = Seq(
      "FINGERPRINT" -> f"0x${ShellRegisters.fingerprint(p)}%08Xu",
      "FINGERPRINT_TEXT" -> s"\"${p.fingerprint}\"",
      "STREAM_BITS" -> p.streamBits.toString,
      "WORDS_PER_BEAT" -> p.wordsPerBeat.toString,
      "DUAL_CLOCK" -> (if (p.dualClock) "1" else "0"),
      "BOX_WORDS" -> p.boxWords.toString,
      "KEY_SLOT_BITS" -> p.keySlotBits.toString,
      "INDEX_WORDS" -> p.indexWords.toString,
      "MASK_WORDS" -> p.maskWords.toString,
      "RECORD_WORDS" -> p.recordWords.toString,
      "TRAILER_WORDS" -> Protocol.TrailerWords.toString,
      "TRAILER_MAGIC" -> f"0x${Protocol.TrailerMagic}%02X",
      "PROTOCOL_VERSION" -> Protocol.Version.toString,
      "ADDRESS_BITS" -> map.addressBits.toString
    )
    val lines =
      params.map { case (k, v) => s"#define BPACCEL_SHELL_$k $v" } ++
        Seq("", "/* Opcodes (command header bits [7:0]) */") ++
        Protocol.opcodes.map(o => f"#define BPACCEL_SHELL_OP_${o.name} 0x${o.code}%02X /* ${o.doc} */") ++
        Seq("", "/* Error codes (trailer word 0 bits [15:8], LAST_REPLY.ERROR) */") ++
        Protocol.errors.map(e => s"#define BPACCEL_SHELL_ERR_${e.name} ${e.code}") ++
        Seq("", "/* Trailer words */") ++
        Protocol.trailerFields.map(f => s"#define BPACCEL_SHELL_TRAILER_${f.name} ${f.word} /* ${f.doc} */") ++
        Seq("", "/* Registers: byte offsets, reset values, fields */") ++
        RegisterMapEmitters.cDefines(map, "BPACCEL_SHELL")
    s"""/* Generated by bpaccel.shell.EmitShell for ${p.fingerprint}; do not edit.
       | * The stream protocol: docs/protocol.md; the registers: docs/registers.md. */
       |#ifndef BPACCEL_SHELL_H
       |#define BPACCEL_SHELL_H
       |
       |${lines.mkString("\n")}
       |
       |#endif /* BPACCEL_SHELL_H */
       |""".stripMargin
  }
}

/** The FuseSoC core file (CAPI2) of one emission: its files, and targets
  * `default` (the RTL), `lint` (Verilator -Wall) and `sim` (Icarus, the smoke
  * testbench, when one was copied beside the Verilog).
  */
object FuseSocCore {
  val fileName = "bpaccel_shell.core"

  def apply(p: ShellParams, files: Seq[Path], smokeTestbench: Option[Path]): String = {
    val rtl = files.map(f => s"      - ${f.getFileName}").mkString("\n")
    val tb = smokeTestbench.map(_.getFileName.toString)
    val tbFileset = tb.fold("")(name => s"""
       |  smoke_tb:
       |    files:
       |      - $name
       |    file_type: systemVerilogSource""".stripMargin)
    // The testbench connects core_clk only where the shell has it (a define, so absent when false).
    val dualClock = if (p.dualClock) Seq("DUAL_CLOCK") else Nil
    val simTarget = tb.fold("")(_ => s"""
       |  sim:
       |    description: Icarus Verilog runs the smoke testbench
       |    default_tool: icarus
       |    filesets: [rtl, smoke_tb]
       |    toplevel: bpaccel_shell_smoke_tb
       |    parameters: [${("STREAM_BITS" +: dualClock).mkString(", ")}]
       |    tools:
       |      icarus:
       |        iverilog_options: [-g2012]""".stripMargin)
    val parameters = tb.fold("")(_ => s"""
       |parameters:
       |  STREAM_BITS:
       |    datatype: int
       |    default: ${p.streamBits}
       |    paramtype: vlogparam""".stripMargin + dualClock.map(d => s"""
       |  $d:
       |    datatype: bool
       |    default: true
       |    paramtype: vlogdefine""".stripMargin).mkString)
    s"""CAPI=2:
       |# Generated by bpaccel.shell.EmitShell for ${p.fingerprint}; do not edit.
       |name: bpaccel:accel:bpaccel_shell:0.1.0
       |description: Broad-phase collision accelerator in an AXI4-Stream / AXI4-Lite shell (docs/integration.md)
       |
       |filesets:
       |  rtl:
       |    files:
       |$rtl
       |    file_type: systemVerilogSource
       |  lint_waivers:
       |    files:
       |      - lint_waivers.vlt
       |    file_type: vlt$tbFileset
       |
       |targets:
       |  default:
       |    filesets: [rtl]
       |    toplevel: BpaccelShell
       |  lint:
       |    description: Verilator lint, every warning on
       |    default_tool: verilator
       |    filesets: [rtl, lint_waivers]
       |    toplevel: BpaccelShell
       |    tools:
       |      verilator:
       |        mode: lint-only
       |        verilator_options: [-Wall]$simTarget
       |$parameters
       |""".stripMargin
  }
}
