package bpaccel

import chisel3._
import chiseltest._
import org.scalatest.Assertions.fail

/** What one run returned, as the consumer saw it. */
case class RunOutcome(
  pairs: Seq[(Int, Int)],                     // every pair of every beat, in arrival order
  probeCycles: Vector[Vector[Option[(Int, Int)]]], // per scheduled cycle, per lane (debug port only)
  error: Int,
  loadCycles: Long,
  cycles: Long,
  issueCycles: Long,
  stallCycles: Long,
  hits: Long,
  driverLoadCycles: Long, // clock steps the driver saw from the run's first load to its start, both included
  driverCycles: Long      // clock steps the driver saw the accelerator busy after the start
)

/** What one batch returned, as the consumer saw it. */
case class BatchOutcome(
  pairs: Seq[(Int, Int, Int)], // (cell tag, i, j) of every beat, in arrival order
  error: Int,
  cellsDone: Long,
  loadCycles: Long,
  cycles: Long,
  issueCycles: Long,
  stallCycles: Long,
  hits: Long,
  driverCycles: Long // clock steps from the cycle that took the first count to the last busy one, both included
)

object AccelDriver {
  /** The pairs of one result beat: bit k of `mask` is objects (iBase + k, jBase + k),
    * both modulo 2^indexWidth (a short stream run's bases are moved down by its
    * head pad and may wrap; see ScheduleBeat).
    */
  def beatPairs(p: AccelParams, iBase: Int, jBase: Int, mask: BigInt): Seq[(Int, Int)] = {
    val wrap = (1 << p.indexWidth) - 1
    (0 until p.m).filter(mask.testBit).map(k => ((iBase + k) & wrap, (jBase + k) & wrap))
  }
}

/** Drives a [[BroadPhaseAccel]] through its ports, one clock at a time. */
class AccelDriver(dut: BroadPhaseAccel, maxCyclesPerRun: Int = 200000) {
  private val p = dut.p
  dut.clock.setTimeout(0)
  // Steps since the first box of the run being loaded (None before its first box).
  private var loadSteps: Option[Long] = None

  private def step(): Unit = {
    dut.clock.step()
    loadSteps = loadSteps.map(_ + 1)
  }

  def idleInputs(): Unit = {
    dut.io.load.valid.poke(false.B)
    dut.io.start.valid.poke(false.B)
    dut.io.start.bits.split.poke(0.U)
    dut.io.cells.valid.poke(false.B)
    dut.io.cells.bits.split.poke(0.U)
    dut.io.result.ready.poke(false.B)
  }

  /** Lets `cycles` clock cycles pass with every input idle. */
  def idle(cycles: Int): Unit = for (_ <- 0 until cycles) step()

  def load(boxes: Seq[Box]): Unit = {
    for (b <- boxes) {
      dut.io.load.valid.poke(true.B)
      pokeBox(b)
      var waited = 0
      while (!dut.io.load.ready.peek().litToBoolean) {
        step(); waited += 1
        if (waited > 100) fail("load.ready stayed low for 100 cycles while idle")
      }
      if (loadSteps.isEmpty) loadSteps = Some(0)
      step()
    }
    dut.io.load.valid.poke(false.B)
  }

  /** Sends start(n, split) for one cycle and returns without waiting for the run. */
  def pulseStart(n: Int, split: Int = 0): Long = {
    dut.io.start.valid.poke(true.B)
    dut.io.start.bits.count.poke(n.U)
    dut.io.start.bits.split.poke(split.U)
    if (!dut.io.start.ready.peek().litToBoolean) fail("start.ready is low while the accelerator is idle")
    step()
    dut.io.start.valid.poke(false.B)
    dut.io.start.bits.split.poke(0.U)
    val loadCycles = loadSteps.getOrElse(1L)
    loadSteps = None
    loadCycles
  }

  /** Sends start(n, split) and plays the consumer until done, with `ready(cycle)` as its pattern. */
  def start(n: Int, ready: Int => Boolean = _ => true, split: Int = 0): RunOutcome = {
    val driverLoadCycles = pulseStart(n, split)

    val pairs  = Seq.newBuilder[(Int, Int)]
    val probes = Vector.newBuilder[Vector[Option[(Int, Int)]]]
    var cycle  = 0
    while (dut.io.status.busy.peek().litToBoolean) {
      if (cycle >= maxCyclesPerRun) fail(s"run of n=$n did not finish within $maxCyclesPerRun cycles")
      val r = ready(cycle)
      dut.io.result.ready.poke(r.B)
      if (r && dut.io.result.valid.peek().litToBoolean) {
        val i0   = dut.io.result.bits.iBase.peek().litValue.toInt
        val j0   = dut.io.result.bits.jBase.peek().litValue.toInt
        val mask = dut.io.result.bits.mask.peek().litValue
        pairs ++= AccelDriver.beatPairs(p, i0, j0, mask)
      }
      dut.io.debug.foreach { d =>
        if (d.cycleValid.peek().litToBoolean)
          probes += Vector.tabulate(p.m) { k =>
            val lane = d.lanes(k)
            if (lane.valid.peek().litToBoolean) Some((lane.i.peek().litValue.toInt, lane.j.peek().litValue.toInt))
            else None
          }
      }
      dut.clock.step()
      cycle += 1
    }
    dut.io.result.ready.poke(false.B)
    if (!dut.io.status.done.peek().litToBoolean) fail("busy fell but done did not rise")
    if (dut.io.result.valid.peek().litToBoolean) fail("a result beat is still waiting after done")
    RunOutcome(
      pairs.result(),
      probes.result(),
      dut.io.status.error.peek().litValue.toInt,
      dut.io.counters.loadCycles.peek().litValue.toLong,
      dut.io.counters.cycles.peek().litValue.toLong,
      dut.io.counters.issueCycles.peek().litValue.toLong,
      dut.io.counters.stallCycles.peek().litValue.toLong,
      dut.io.counters.hits.peek().litValue.toLong,
      driverLoadCycles,
      cycle.toLong
    )
  }

  private def pokeBox(b: Box): Unit =
    for (a <- 0 until 3) {
      dut.io.load.bits.min(a).poke(b.min(a).U(p.keyWidth.W))
      dut.io.load.bits.max(a).poke(b.max(a).U(p.keyWidth.W))
    }

  /** Runs `cells` as one batch: offers the next count and the next box every
    * cycle (counts first when both are offered at once, as the port wants),
    * and plays the consumer with `ready(cycle)` until the batch is over.
    */
  def batch(cells: Seq[Seq[Box]], ready: Int => Boolean = _ => true, splits: Seq[Int] = Nil): BatchOutcome = {
    val counts = cells.map(_.length)
    require(splits.isEmpty || splits.length == cells.length, "one split per cell")
    val boxes  = cells.flatten // each cell in index order
    var nextCount, nextBox = 0
    var began = false
    val pairs = Seq.newBuilder[(Int, Int, Int)]
    var cycle, busyCycles = 0
    while (nextCount < counts.length || nextBox < boxes.length || dut.io.status.busy.peek().litToBoolean) {
      if (cycle >= maxCyclesPerRun) fail(s"batch of ${counts.length} cells did not finish within $maxCyclesPerRun cycles")
      val countOffered = nextCount < counts.length
      dut.io.cells.valid.poke(countOffered.B)
      if (countOffered) {
        dut.io.cells.bits.count.poke(counts(nextCount).U)
        dut.io.cells.bits.split.poke(splits.lift(nextCount).getOrElse(0).U)
      }
      val boxOffered = nextBox < boxes.length
      dut.io.load.valid.poke(boxOffered.B)
      if (boxOffered) pokeBox(boxes(nextBox))
      val r = ready(cycle)
      dut.io.result.ready.poke(r.B)
      if (began) busyCycles += 1
      if (countOffered && dut.io.cells.ready.peek().litToBoolean) {
        if (!began) { began = true; busyCycles = 1 }
        nextCount += 1
      }
      if (boxOffered && dut.io.load.ready.peek().litToBoolean) nextBox += 1
      if (r && dut.io.result.valid.peek().litToBoolean) {
        val cell = dut.io.result.bits.cell.peek().litValue.toInt
        val i0   = dut.io.result.bits.iBase.peek().litValue.toInt
        val j0   = dut.io.result.bits.jBase.peek().litValue.toInt
        val mask = dut.io.result.bits.mask.peek().litValue
        for ((i, j) <- AccelDriver.beatPairs(p, i0, j0, mask)) pairs += ((cell, i, j))
      }
      step()
      cycle += 1
    }
    dut.io.cells.valid.poke(false.B)
    dut.io.load.valid.poke(false.B)
    dut.io.result.ready.poke(false.B)
    if (!dut.io.status.done.peek().litToBoolean) fail("the batch ended but done did not rise")
    if (dut.io.status.batch.peek().litToBoolean) fail("status.batch is still set after the batch")
    if (dut.io.result.valid.peek().litToBoolean) fail("a result beat is still waiting after the batch")
    loadSteps = None
    BatchOutcome(
      pairs.result(),
      dut.io.status.error.peek().litValue.toInt,
      dut.io.status.cellsDone.peek().litValue.toLong,
      dut.io.counters.loadCycles.peek().litValue.toLong,
      dut.io.counters.cycles.peek().litValue.toLong,
      dut.io.counters.issueCycles.peek().litValue.toLong,
      dut.io.counters.stallCycles.peek().litValue.toLong,
      dut.io.counters.hits.peek().litValue.toLong,
      busyCycles.toLong
    )
  }

  def run(boxes: Seq[Box], ready: Int => Boolean = _ => true, split: Int = 0): RunOutcome = {
    load(boxes)
    start(boxes.length, ready, split)
  }
}
