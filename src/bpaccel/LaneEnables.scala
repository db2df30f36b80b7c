package bpaccel

import java.nio.file.{Files, Path}

/** Checks, in the emitted StreamLanes.sv, that each lane register of the
  * stream engine (lane k of the window, `aNext`, `a` and the head chain) is
  * assigned only under enable copies of its own lane (`*_replica<k>`).
  *
  * firtool 1.62.1, merging the always blocks of sibling registers, now and
  * then put one lane's assignment under another lane's copy (window lane 2
  * under `headShift_replica1`); a CI build of such a file computed wrong
  * pairs. `--emit-separate-always-blocks` has stopped it in every run
  * since, and this check makes sure of it in every emission, host and FPGA
  * flow alike, rather than only where a simulation happens to meet the
  * broken lane.
  */
object LaneEnables {
  /** The emitted module that holds the lanes ([[StreamLanes]]). */
  val file = "StreamLanes.sv"
  private val AlwaysBlock = """(?s)always @\(posedge clock\) begin(.*?)end // always @\(posedge\)""".r
  private val LaneAssignment = """\b(window|aNext|a|headRegs)_(\d+)_\w+\s*<=""".r
  private val EnableCopy = """\b(\w+)_replica(\d+)\b""".r

  /** Every (assignment, enable copy) in `text` whose lanes differ. Each
    * `always` block is one register's (--emit-separate-always-blocks).
    */
  def mismatches(text: String): Seq[(String, String)] =
    AlwaysBlock.findAllMatchIn(text).toSeq.flatMap { block =>
      val body   = block.group(1)
      val copies = EnableCopy.findAllMatchIn(body).toSeq
      for (reg <- LaneAssignment.findAllMatchIn(body).toSeq; copy <- copies if copy.group(2) != reg.group(2))
        yield (reg.matched, copy.matched)
    }.distinct

  /** Lanes k < m whose `<vector>_k_box` is assigned under none of its lane's enable copies. */
  def unguarded(text: String, m: Int): Seq[String] =
    for {
      k   <- 0 until m
      reg <- Seq("window", "aNext", "a")
      if !s"if \\((\\w+)_replica$k\\)\\s+${reg}_${k}_box <=".r.findFirstIn(text).isDefined
    } yield s"${reg}_${k}_box"

  /** Throws naming the first wrong lane, for a stream configuration's emitted folder. */
  def check(p: AccelParams, dir: Path): Unit = {
    val text = Files.readString(dir.resolve(file))
    for ((reg, copy) <- mismatches(text).headOption)
      throw new IllegalStateException(
        s"LaneEnables: $file assigns '$reg' under '$copy', another lane's enable: firtool miscompiled it; emit again")
    for (reg <- unguarded(text, p.m).headOption)
      throw new IllegalStateException(s"LaneEnables: $file assigns $reg under none of its lane's enable copies")
  }
}
