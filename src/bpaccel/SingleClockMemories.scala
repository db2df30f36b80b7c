package bpaccel

import java.nio.file.{Files, Path}

import scala.jdk.CollectionConverters._

/** Gives every memory module firtool emits one clock port.
  *
  * firtool builds each `SyncReadMem` as a module `mem_<depth>x<width>` with a
  * clock per port (`R0_clk`, `W0_clk`), all tied to the same clock by the
  * instance. Synthesised on its own (out of context), that module has two
  * clocks as far as Yosys knows: it refuses to merge the read-address register
  * into the block RAM ("address FF clock is not compatible with write clock")
  * and falls back to LUT RAM. firtool has no option to emit one clock, so this
  * rewrites the emitted text: the module's port clocks become one `clock`
  * input, and each instance connects it once. It only accepts what it
  * understands: a module whose clocks are exactly `R0_clk` and `W0_clk`, and
  * instances that tie both to the same signal; anything else is an error.
  */
object SingleClockMemories {
  val clockPort = "clock"
  private val portClocks = Seq("R0_clk", "W0_clk")

  /** One ANSI port declaration of firtool's port list (a line without a
    * direction or range inherits both from the line before it).
    */
  private val PortLine = """^\s*(input|output)?\s*(\[[^\]]+\])?\s*(\w+)\s*,?\s*$""".r

  /** Rewrites the memory modules `mem_*.sv` that `dir/filelist.f` lists and their instances in
    * the other files it lists (only those: firtool leaves older files of the folder alone).
    */
  def rewrite(dir: Path): Seq[String] = {
    val svFiles  = listedFiles(dir)
    val memories = svFiles.filter(isMemory)
    val names = memories.map { f =>
      val (name, text) = rewriteModule(Files.readString(f), f.getFileName.toString)
      Files.writeString(f, text)
      name
    }
    if (names.nonEmpty)
      for (f <- svFiles if !memories.contains(f)) {
        val text = Files.readString(f)
        val out  = rewriteInstances(text, names, f.getFileName.toString)
        if (out != text) Files.writeString(f, out)
      }
    names
  }

  /** The SystemVerilog files `dir/filelist.f` lists (only those: firtool leaves older files of the folder alone). */
  def listedFiles(dir: Path): Seq[Path] =
    Files.readAllLines(dir.resolve("filelist.f")).asScala.map(_.trim).filter(_.endsWith(".sv")).map(dir.resolve(_)).toSeq

  /** The memory modules firtool emits for `SyncReadMem`s: `mem_<depth>x<width>.sv`. */
  def memoryFiles(dir: Path): Seq[Path] = listedFiles(dir).filter(isMemory)

  private def isMemory(file: Path): Boolean = file.getFileName.toString.startsWith("mem_")

  private def rewriteModule(text: String, file: String): (String, String) = {
    val header = """(?s)module\s+(\w+)\s*\((.*?)\);""".r
    val h = header.findFirstMatchIn(text).getOrElse(fail(file, "no module header"))
    var direction = ""
    var range     = ""
    val ports = h.group(2).linesIterator.map(_.trim).filter(_.nonEmpty).map {
      case PortLine(d, r, name) =>
        if (d != null) { direction = d; range = Option(r).getOrElse("") }
        else if (r != null) range = r
        (direction, range, name)
      case line => fail(file, s"unexpected port line '$line'")
    }.toSeq
    val clocks = ports.map(_._3).filter(_.endsWith("_clk"))
    if (clocks.sorted != portClocks.sorted) fail(file, s"expected clocks ${portClocks.mkString(", ")}, found ${clocks.mkString(", ")}")
    val kept = ports.filterNot(_._3 == "W0_clk").map {
      case (d, r, "R0_clk") => (d, r, clockPort)
      case port             => port
    }
    val list = kept.map { case (d, r, n) => s"  ${d.padTo(6, ' ')} ${r.padTo(8, ' ')} $n" }.mkString(",\n")
    val body = text.substring(h.end).replaceAll("""\b(R0_clk|W0_clk)\b""", clockPort)
    (h.group(1), text.substring(0, h.start) + s"module ${h.group(1)}(\n$list\n);" + body)
  }

  private def rewriteInstances(text: String, memories: Seq[String], file: String): String = {
    val instance = s"""(?s)(\\b(?:${memories.mkString("|")})\\s+\\w+\\s*\\()(.*?)(\\n\\s*\\);)""".r
    instance.replaceAllIn(text, { mt =>
      val connections = topLevelItems(mt.group(2))
      for (c <- connections if !c.startsWith("."))
        fail(file, s"instance '${mt.group(1).trim}': unexpected connection '$c'")
      def signal(port: String): String = {
        val c = connections.filter(_.startsWith(s".$port"))
        if (c.length != 1) fail(file, s"instance '${mt.group(1).trim}' connects $port ${c.length} times")
        c.head.stripPrefix(s".$port").trim
      }
      if (signal("R0_clk") != signal("W0_clk"))
        fail(file, s"instance '${mt.group(1).trim}' clocks its ports differently: ${signal("R0_clk")} and ${signal("W0_clk")}")
      val kept = connections.filterNot(_.startsWith(".W0_clk")).map(c =>
        if (c.startsWith(".R0_clk")) s".$clockPort ${c.stripPrefix(".R0_clk").trim}" else c
      )
      scala.util.matching.Regex.quoteReplacement(mt.group(1) + kept.map("\n    " + _).mkString(",") + mt.group(3))
    })
  }

  /** The comma-separated items of a port connection list, ignoring commas inside (), {} and []. */
  private def topLevelItems(list: String): Seq[String] = {
    val items = Seq.newBuilder[String]
    val item  = new StringBuilder
    var depth = 0
    for (ch <- list) ch match {
      case '(' | '{' | '[' => depth += 1; item += ch
      case ')' | '}' | ']' => depth -= 1; item += ch
      case ',' if depth == 0 => items += item.result().trim; item.clear()
      case _ => item += ch
    }
    items += item.result().trim
    items.result().filter(_.nonEmpty)
  }

  private def fail(file: String, what: String): Nothing =
    throw new IllegalStateException(s"SingleClockMemories: $file: $what")
}
