package bpaccel.binning

import org.scalatest.matchers.should.Matchers

import bpaccel.Box

/** What every frame run on the hardware must satisfy. */
trait BinningChecks extends Matchers {

  /** Pairs against brute force: each overlapping pair exactly once, i < j, nothing else. */
  def checkPairs(f: BinFrame, out: FrameOutcome): Unit = {
    val pairs = out.pairs
    pairs.foreach { case (i, j) => withClue(s"pair ($i, $j): ") { i should be < j; j should be < f.boxes.length } }
    pairs.distinct.length shouldBe pairs.length
    pairs.toSet shouldBe Box.bruteForcePairs(f.boxes)
    out.records shouldBe pairs.length.toLong
  }

  /** The hardware against the cycle model, event by event: entry writes, each group's schedule
    * cycles and lanes, every output beat and its cycle, the summary's cycle and every counter.
    */
  def checkAgainstModel(p: BinningParams, out: FrameOutcome, model: BinningCycleModel.Result, debug: Boolean): Unit = {
    BinningErrorCode.name(out.error) shouldBe BinningErrorCode.name(model.error)
    out.detail shouldBe model.detail
    if (debug) {
      out.writes shouldBe model.writes
      for (gr <- 0 until p.groups) withClue(s"group $gr's schedule cycles: ") {
        val expected = model.ops(gr).filterNot(_.op.bubble).map(o => (o.cycle + p.hitLatency, o.op.lanes))
        out.issues(gr) shouldBe expected
      }
    }
    out.beats shouldBe model.beats
    out.summaryCycle shouldBe model.summaryCycle
    out.cycles shouldBe model.cycles
    out.records shouldBe model.pairs.length.toLong
    out.boxes shouldBe model.boxesReceived
    out.entries shouldBe model.writes.length.toLong
    out.maxGroupEntries shouldBe (if (model.writes.isEmpty) 0L else model.writes.groupBy(_.group).values.map(_.length).max.toLong)
    out.intakeCycles shouldBe (if (model.error == BinningErrorCode.None) model.intakeDone + 1 else 0L)
    out.issueCycles shouldBe model.issueCycles
    out.stallCycles shouldBe model.stallCycles
  }
}
