package bpaccel

import java.nio.file.{Files, Path, Paths}

import chisel3.stage.ChiselGeneratorAnnotation
import circt.stage.{ChiselStage, FirtoolOption}

/** Emits the SystemVerilog of one configuration plus its C header and
  * parameter file (bpaccel_params.h, bpaccel_params.json).
  *
  * Usage: EmitVerilog --arch stream --m 16 --capacity 4096 --target-dir generated/stream-m16
  */
object EmitVerilog {
  /** Raw command-line values; turned into [[AccelParams]] (and checked) once all are read. */
  private case class Options(
    m: Int = AccelParams().m,
    capacity: Option[Int] = None,
    keyWidth: Int = AccelParams().keyWidth,
    queueDepth: Int = AccelParams().resultQueueDepth,
    memoryOutputStages: Int = AccelParams().memoryOutputStages,
    debugPort: Boolean = false,
    arch: String = AccelParams().arch.name,
    batchCells: Int = AccelParams().batchCells,
    memoryStyle: String = AccelParams().memoryStyle.name,
    targetDir: Path = Paths.get("generated")
  ) {
    def params: AccelParams = {
      val a = Arch.fromName(arch)
      AccelParams(
        m,
        capacity.getOrElse(a.defaultCapacity(m)),
        keyWidth,
        queueDepth,
        memoryOutputStages,
        debugPort,
        a,
        batchCells = batchCells,
        memoryStyle = MemoryStyle.fromName(memoryStyle)
      )
    }
  }

  /** firtool options that keep the output plain enough for Yosys, Verilator and vendor tools.
    *
    * `--emit-separate-always-blocks`: firtool 1.62.1, merging the always
    * blocks of sibling registers, now and then put a register's assignment
    * under another's enable (StreamEngine: the start's copy into window lane
    * 0 under `headShift_replica8`): from one CHIRRTL file, 1 in 24 and 8 in
    * 36 runs of firtool gave a different StreamEngine.sv, and a CI build of
    * such a file computed wrong pairs. With the option, 60 runs gave one
    * file, with each copy under its own `headCopy` enable; [[LaneEnables]]
    * checks every emission for it.
    */
  val firtoolOptions: Array[String] = Array(
    "--emit-separate-always-blocks",
    "-disable-all-randomization",
    "-strip-debug-info",
    "--lowering-options=disallowLocalVariables,disallowPackedArrays,locationInfoStyle=none"
  )

  def emit(p: AccelParams, targetDir: Path): Path = {
    Files.createDirectories(targetDir)
    // One file per module (what lint and FPGA flows expect) plus filelist.f.
    (new ChiselStage).execute(
      Array("--target", "systemverilog", "--split-verilog", "--target-dir", targetDir.toString),
      Seq(ChiselGeneratorAnnotation(() => new BroadPhaseAccel(p))) ++ firtoolOptions.map(FirtoolOption(_))
    )
    finishCore(p, targetDir)
    Files.writeString(targetDir.resolve(lintWaivers), lintWaiverText)
    targetDir.resolve("filelist.f")
  }

  /** What every emission holding the core of `p` gets after firtool: its
    * memories rewritten for block RAM, the architecture's checks, and the C
    * header and parameter file.
    */
  def finishCore(p: AccelParams, targetDir: Path): Unit = {
    // One clock port per memory, so each maps to block RAM when synthesised on its own.
    SingleClockMemories.rewrite(targetDir)
    // No read meets a write at the same row, so the block RAM needs no collision bypass.
    NoCollisionMemories.rewrite(targetDir)
    p.arch.checkEmitted(p, targetDir)
    val memory = p.memoryStyle.moduleName(p.memoryRows, p.memoryWidth)
    if (!SingleClockMemories.listedFiles(targetDir).exists(_.getFileName.toString == s"$memory.sv"))
      throw new IllegalStateException(s"EmitVerilog: no $memory.sv in $targetDir/filelist.f, which the parameter file names")
    Files.writeString(targetDir.resolve(CHeader.fileName), CHeader(p))
    Files.writeString(targetDir.resolve(ParamsJson.fileName), ParamsJson(p))
  }

  /** Verilator configuration for `verilator --lint-only -Wall lint_waivers.vlt -F filelist.f`. */
  val lintWaivers = "lint_waivers.vlt"

  /** firtool builds the result queue's storage (chisel3.util.Queue's Mem, read
    * combinationally) as a module with a read clock it never uses.
    */
  private val lintWaiverText =
    "`verilator_config\n" +
      "// chisel3.util.Queue's memory reads combinationally: firtool's ram module has an unused read clock.\n" +
      "lint_off -rule UNUSEDSIGNAL -file \"*ram_*.sv\" -match \"*R0_clk*\"\n"


  def main(args: Array[String]): Unit = {
    val parser = new scopt.OptionParser[Options]("EmitVerilog") {
      head("Emits the broad-phase accelerator's SystemVerilog and C header")
      opt[Int]("m").action((v, o) => o.copy(m = v)).text("parallelism: pair tests per cycle")
      opt[Int]("capacity")
        .action((v, o) => o.copy(capacity = Some(v)))
        .text(s"objects per run (default: the architecture's, ${Arch.all.map(a => s"${a.name} ${a.defaultCapacity(AccelParams().m)}").mkString(", ")} at m = ${AccelParams().m}; seed: a multiple of m)")
      opt[Int]("key-width").action((v, o) => o.copy(keyWidth = v)).text("bits per coordinate key")
      opt[Int]("queue-depth").action((v, o) => o.copy(queueDepth = v)).text("result queue beats")
      opt[Int]("memory-output-stages")
        .action((v, o) => o.copy(memoryOutputStages = v))
        .text("registers after the memories' read data (default 2)")
      opt[Boolean]("debug-port").action((v, o) => o.copy(debugPort = v)).text("add the per-lane debug probe")
      opt[String]("arch")
        .action((v, o) => o.copy(arch = v))
        .text(s"architecture: ${Arch.all.map(_.name).mkString(" or ")} (default ${AccelParams().arch.name})")
      opt[Int]("batch-cells")
        .action((v, o) => o.copy(batchCells = v))
        .text(s"cell counts the batch queue holds (default ${AccelParams().batchCells})")
      opt[String]("memory-style")
        .action((v, o) => o.copy(memoryStyle = v))
        .text(
          s"coordinate memories: ${MemoryStyle.all.map(_.name).mkString(" or ")} " +
            s"(default ${AccelParams().memoryStyle.name}; see docs/fpga.md)"
        )
      opt[String]("target-dir").action((v, o) => o.copy(targetDir = Paths.get(v))).text("output folder")
    }
    // Parameters are validated when the case class is built; report that as a usage error.
    parser.parse(args, Options()) match {
      case Some(o) =>
        val params = Emitter.parametersOrExit("EmitVerilog")(o.params)
        val out = emit(params, o.targetDir)
        println(s"wrote $out, ${CHeader.fileName} and ${ParamsJson.fileName} for $params")
      case None => sys.exit(2)
    }
  }
}
