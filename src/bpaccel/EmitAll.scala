package bpaccel

/** Runs several emitters in one JVM, in order:
  * {{{EmitAll EmitShell <its options> + EmitBinning <its options> + EmitVerilog <its options>}}}
  * sbt forks a JVM for each `runMain`, and for a small design its start and
  * warm-up cost more than the emission: `make test` emits five designs. An
  * emitter that fails ends the JVM with its own status, as it would alone.
  */
object EmitAll {
  private val emitters: Map[String, Array[String] => Unit] = Map(
    "EmitVerilog" -> EmitVerilog.main,
    "EmitShell"   -> shell.EmitShell.main,
    "EmitBinning" -> binning.EmitBinning.main
  )

  /** The commands between the separators; empty ones (a trailing `+`) are dropped. */
  def commands(args: Seq[String]): Seq[Seq[String]] =
    args.foldLeft(Vector(Vector.empty[String])) { (acc, arg) =>
      if (arg == "+") acc :+ Vector.empty else acc.init :+ (acc.last :+ arg)
    }.filter(_.nonEmpty)

  def main(args: Array[String]): Unit =
    for (command <- commands(args.toSeq)) emitters.get(command.head) match {
      case Some(emit) => emit(command.tail.toArray)
      case None =>
        System.err.println(s"EmitAll: no emitter ${command.head} (one of ${emitters.keys.toSeq.sorted.mkString(", ")})")
        sys.exit(2)
    }
}

/** What the emitters' mains share. */
object Emitter {
  /** The parameters `build` makes; a failed requirement is a usage error naming the emitter (status 2). */
  def parametersOrExit[P](emitter: String)(build: => P): P =
    try build
    catch {
      case e: IllegalArgumentException =>
        System.err.println(s"$emitter: invalid parameters: ${e.getMessage.stripPrefix("requirement failed: ")}")
        sys.exit(2)
    }
}
