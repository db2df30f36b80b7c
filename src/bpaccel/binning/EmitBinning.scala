package bpaccel.binning

import java.nio.file.{Files, Path, Paths}

import chisel3.stage.ChiselGeneratorAnnotation
import circt.stage.{ChiselStage, FirtoolOption}

import bpaccel.{DistributedMemories, EmitVerilog, Emitter, MemoryStyle, NoCollisionMemories, RegisterMemories, SingleClockMemories}

/** Emits one binning configuration: SystemVerilog (one file per module and
  * filelist.f), its C header and its JSON parameter file.
  *
  * ./scripts/sbt "runMain bpaccel.binning.EmitBinning --target-dir generated/binning"
  */
object EmitBinning {
  val headerFile = "bpaccel_binning_params.h"
  val jsonFile   = "bpaccel_params.json"

  def emit(p: BinningParams, targetDir: Path): Path = {
    Files.createDirectories(targetDir)
    (new ChiselStage).execute(
      Array("--target", "systemverilog", "--split-verilog", "--target-dir", targetDir.toString),
      Seq(ChiselGeneratorAnnotation(() => new BinningCore(p))) ++ EmitVerilog.firtoolOptions.map(FirtoolOption(_))
    )
    finishCore(p, targetDir)
    Files.writeString(targetDir.resolve(EmitVerilog.lintWaivers), lintWaiverText)
    targetDir.resolve("filelist.f")
  }

  /** What an emission of the core needs after firtool, alone or inside the stream shell: its memories
    * rewritten for block and LUT RAM, its C header and JSON parameter file.
    */
  def finishCore(p: BinningParams, targetDir: Path): Unit = {
    SingleClockMemories.rewrite(targetDir)
    NoCollisionMemories.rewrite(targetDir)
    // The table's module must not be an entry or order memory's too (same rows and width), or those would go to LUT RAM.
    val table = CellTable.memoryModule(p)
    if (Seq(p.entryBits, p.entryAddrWidth).map(w => s"mem_${p.groupCapacity}x$w").contains(table))
      throw new IllegalArgumentException(s"EmitBinning: the cell table's memory module $table is also a group memory's; " +
        "change groupCapacity or cellBits")
    DistributedMemories.rewrite(targetDir, Seq(table))
    // The two-entry queues (128 lane queues at the defaults) cost fewer LUT4 positions as flip-flops than as LUT RAM.
    RegisterMemories.rewrite(targetDir)
    emitParams(p, targetDir)
  }

  /** chisel3.util.Queue's memory reads combinationally: firtool's ram module has a read clock it never uses. */
  private val lintWaiverText =
    "`verilator_config\n" +
      "lint_off -rule UNUSEDSIGNAL -file \"*ram_*.sv\" -match \"*R0_clk*\"\n"

  /** The C header and JSON parameter file alone (what the host is compiled against), without the Verilog. */
  def emitParams(p: BinningParams, targetDir: Path): Unit = {
    Files.createDirectories(targetDir)
    Files.writeString(targetDir.resolve(headerFile), BinningHeader.cHeader(p))
    Files.writeString(targetDir.resolve(jsonFile), BinningHeader.json(p))
  }

  /** EmitBinning's command line: the core's settings, applied in one step, and where the files go. */
  final case class Options(b: BinningOptions = BinningOptions(), targetDir: Path = Paths.get("generated/binning"),
                           paramsOnly: Boolean = false)

  /** The options `args` give, or None when they do not parse (scopt has then printed why). */
  def parse(args: Seq[String]): Option[Options] = {
    val d = BinningParams()
    val parser = new scopt.OptionParser[Options]("EmitBinning") {
      head("Emits the binning device's SystemVerilog, C header and JSON parameters")
      opt[Seq[Int]]("group-bits")(BinningOptions.groupBitsRead).action((v, o) => o.copy(b = o.b.copy(groupBits = Some(v))))
        .text(s"ax,ay,az: 2^a groups per axis (default ${d.groupBits.mkString(",")})")
      opt[Int]("lanes-per-group").action((v, o) => o.copy(b = o.b.copy(lanesPerGroup = Some(v)))).text(s"g (default ${d.g})")
      opt[Int]("key-width").action((v, o) => o.copy(b = o.b.copy(keyWidth = Some(v)))).text(s"default ${d.keyWidth}")
      opt[Int]("cell-bits").action((v, o) => o.copy(b = o.b.copy(cellBits = Some(v)))).text(s"default ${d.cellBits}")
      opt[Int]("box-capacity").action((v, o) => o.copy(b = o.b.copy(boxCapacity = Some(v)))).text(s"default ${d.boxCapacity}")
      opt[Int]("group-capacity").action((v, o) => o.copy(b = o.b.copy(groupCapacity = Some(v))))
        .text(s"default ${d.groupCapacity}")
      opt[Int]("intake-boxes").action((v, o) => o.copy(b = o.b.copy(intakeBoxes = Some(v)))).text(s"default ${d.intakeBoxes}")
      opt[Int]("pairs-per-beat").action((v, o) => o.copy(b = o.b.copy(pairsPerBeat = Some(v))))
        .text(s"default ${d.pairsPerBeat}")
      opt[Int]("memory-output-stages").action((v, o) => o.copy(b = o.b.copy(memoryOutputStages = Some(v))))
        .text(s"default ${d.memoryOutputStages}")
      opt[String]("memory-style").action((v, o) => o.copy(b = o.b.copy(memoryStyle = Some(v))))
        .text(s"${MemoryStyle.all.map(_.name).mkString(" or ")} (default ${d.memoryStyle.name})")
      opt[Boolean]("debug-port").action((v, o) => o.copy(b = o.b.copy(debugPort = Some(v))))
      opt[Unit]("params-only").action((_, o) => o.copy(paramsOnly = true))
        .text("write only the C header and the JSON parameter file")
      opt[String]("target-dir").action((v, o) => o.copy(targetDir = Paths.get(v))).text("output folder")
    }
    parser.parse(args, Options())
  }

  def main(args: Array[String]): Unit = {
    parse(args.toSeq) match {
      case Some(o) =>
        val p = Emitter.parametersOrExit("EmitBinning")(o.b.params())
        if (o.paramsOnly) {
          emitParams(p, o.targetDir)
          println(s"wrote $headerFile and $jsonFile in ${o.targetDir} for $p")
        } else println(s"wrote ${emit(p, o.targetDir)}, $headerFile and $jsonFile for $p")
      case None => sys.exit(2)
    }
  }
}
