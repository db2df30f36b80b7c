package bpaccel

import java.nio.file.{Files, Path}

import scala.util.matching.Regex

/** Puts a synthesis attribute on the array of a memory module firtool emits. */
object MemoryAttributes {
  /** The one array declaration of a firtool memory module, after any attributes already on it:
    * `reg [w:0] Memory[0:d];`.
    */
  private val ArrayDeclaration = """(?m)^(\s*(?:\(\*.*?\*\)\s*)*)(reg\s+\[[^\]]+\]\s+Memory\s*\[[^\]]+\]\s*;)""".r

  /** Marks the array of the memory module in `path` with `attribute` (once); `by` names the caller in errors. */
  def mark(path: Path, attribute: String, by: String): Unit = {
    val file = path.getFileName.toString
    val text = Files.readString(path)
    val declarations = ArrayDeclaration.findAllMatchIn(text).length
    if (declarations != 1)
      throw new IllegalStateException(s"$by: $file: expected one 'reg [..] Memory[..];', found $declarations")
    if (!text.contains(attribute))
      Files.writeString(path, ArrayDeclaration.replaceAllIn(text, m => Regex.quoteReplacement(s"${m.group(1)}$attribute ${m.group(2)}")))
  }
}

/** Asks synthesis to build chosen memory modules from LUT RAM (distributed
  * RAM) rather than block RAM, in the words of the major vendors' tools:
  * `ram_style` (Vivado), `ramstyle` (Quartus, whose LUT RAM is the MLAB) and
  * `syn_ramstyle` (Synplify, Lattice's synthesis). Yosys 0.23 honours each of
  * the three (BinningEmissionSpec checks that synth_ecp5 maps such a memory
  * to TRELLIS_DPR16X4). For small tables that block RAM would waste: an
  * 18 Kbit DP16KD for a table of a few hundred bits.
  */
object DistributedMemories {
  val attribute = """(* ram_style = "distributed", ramstyle = "MLAB", syn_ramstyle = "distributed" *)"""

  /** Marks the memory modules `modules` (names as `mem_<depth>x<width>`) of the configuration in `dir`. */
  def rewrite(dir: Path, modules: Seq[String]): Unit = {
    val files = SingleClockMemories.memoryFiles(dir)
    for (module <- modules) {
      val file = files.find(_.getFileName.toString == s"$module.sv").getOrElse(
        throw new IllegalStateException(s"DistributedMemories: $dir/filelist.f lists no memory module $module"))
      MemoryAttributes.mark(file, attribute, "DistributedMemories")
    }
  }
}

/** Asks synthesis to build the smallest queue memories from flip-flops
  * rather than LUT RAM, in the same three tools' words (Yosys honours each).
  * chisel3.util.Queue's memory is a `Mem`, which firtool emits as
  * `ram_<depth>x<width>`. On the ECP5 a TRELLIS_DPR16X4 (16 rows x 4 bits)
  * takes 6 LUT4 positions however few rows are used, so W bits of LUT RAM
  * cost 1.5 W LUT4 at any depth up to 16; as registers, 2 rows cost W LUT4
  * (a 2:1 read mux a bit) and 2 W flip-flops, 4 rows already 2 W LUT4 (a 4:1
  * mux a bit). Registers therefore win up to depth 2 only.
  */
object RegisterMemories {
  val attribute = """(* ram_style = "registers", ramstyle = "logic", syn_ramstyle = "registers" *)"""
  val maxDepth  = 2

  private val QueueMemory = """ram_(\d+)x(\d+)\.sv""".r

  /** Marks every queue memory `ram_<depth>x<width>` of at most `maxDepth` rows in `dir`; returns their module names. */
  def rewrite(dir: Path): Seq[String] =
    SingleClockMemories.listedFiles(dir).flatMap { file =>
      file.getFileName.toString match {
        case QueueMemory(depth, _) if depth.toInt <= maxDepth =>
          MemoryAttributes.mark(file, attribute, "RegisterMemories")
          Some(file.getFileName.toString.stripSuffix(".sv"))
        case _ => None
      }
    }
}
