package bpaccel

import org.scalatest.matchers.should.Matchers

/** Assertions shared by the hardware specs: what every run must satisfy. */
trait Checks extends Matchers {

  /** Pairs, counters and cycle accounting of one run against the reference. */
  def checkRun(p: AccelParams, boxes: Seq[Box], out: RunOutcome, consumerNeverStalls: Boolean, split: Int = 0): Unit = {
    val n = boxes.length
    out.error shouldBe AccelError.code(AccelError.None)
    out.pairs.foreach { case (i, j) =>
      withClue(s"pair ($i, $j): ") { i should be < j; j should be < n }
    }
    out.pairs.distinct.length shouldBe out.pairs.length // nothing reported twice
    out.pairs.toSet shouldBe Box.bruteForcePairs(boxes, split) // nothing missed, nothing extra
    out.hits shouldBe out.pairs.length.toLong
    out.issueCycles shouldBe Schedule.issueCycles(n, p.m, split)
    // The hardware's counters against the clock steps the driver itself saw.
    out.cycles shouldBe out.driverCycles
    out.loadCycles shouldBe out.driverLoadCycles
    out.loadCycles shouldBe n + 1L // the driver loads one box a cycle, then starts
    out.cycles shouldBe out.issueCycles + out.stallCycles + p.fixedCycles(n)
    if (consumerNeverStalls) out.stallCycles shouldBe 0
  }

  /** The hardware's per-lane probes against the golden model, cycle by cycle.
    *
    * The golden models run every block from lane 0. The stream's lanes hold a
    * run of L < m + 1 loaded boxes (`loaded`, by default n) from lane d = m + 1 - L up (the
    * loader's head pad; the probes show the engine's lanes, as the unshifted
    * hit mask does), so its expectation is moved up by d lanes; the lanes it
    * moves out past m - 1 must be idle in the model.
    */
  def checkSchedule(p: AccelParams, n: Int, out: RunOutcome, split: Int = 0, loaded: Option[Int] = None): Unit = {
    val golden = p.arch match {
      case Arch.Seed   => require(split == 0, "the seed runs no bipartite runs"); SeedScheduleModel.cycles(n, p.m)
      case Arch.Stream => StreamScheduleModel.cycles(n, p.m, p.readLatency, split)
    }
    val pad = if (p.arch == Arch.Stream) (p.headObjects - loaded.getOrElse(n)).max(0) else 0
    out.probeCycles.length shouldBe golden.length
    for (((hw, gm), c) <- out.probeCycles.zip(golden).zipWithIndex)
      withClue(s"m=${p.m} n=$n split=$split cycle $c (head pad $pad): ") {
        gm.drop(p.m - pad).flatten shouldBe empty // nothing the lanes could not hold
        hw shouldBe (Vector.fill(pad)(None) ++ gm.take(p.m - pad))
      }
  }
}
