package bpaccel

import chisel3._
import chiseltest._
import org.scalatest.exceptions.TestFailedException
import org.scalatest.flatspec.AnyFlatSpec

import scala.util.Random

/** Batches: cells run back to back by the front end give, per cell, exactly
  * the pairs of that cell, tagged with it, and counters that add up to the
  * cells' single runs plus the front end's own cycles.
  */
class BatchSpec extends AnyFlatSpec with Simulators with Checks {

  /** Box counts that hit the edges: empty, one box, one pair, one block, one past it, the capacity. */
  private def cellSizes(rng: Random, p: AccelParams, cells: Int): Seq[Int] = {
    val edges = Seq(0, 1, 2, p.m, p.m + 1, p.capacity).filter(_ <= p.capacity)
    Seq.fill(cells)(if (rng.nextInt(3) == 0) rng.nextInt(p.capacity + 1) else edges(rng.nextInt(edges.length)))
  }

  private def cellBoxes(rng: Random, p: AccelParams, n: Int): Seq[Box] = {
    val scenes = Box.Scenes.all(rng, n, p.keyWidth)
    scenes(rng.nextInt(scenes.length))._2
  }

  private def readyPatterns(seed: Int): Seq[(String, Int => Boolean)] = Seq(
    "always ready"       -> (_ => true),
    "ready 1 cycle in 3" -> (c => c % 3 == 0),
    "random 40%"         -> { val r = new Random(seed); _ => r.nextInt(5) < 2 }
  )

  /** The front end's own cycles: one per batch (its first count) and one per cell (its end). */
  private def frontEndCycles(cells: Int): (Long, Long) = (1L, cells.toLong)

  /** Pairs per cell against the golden model, tags in cell order, counters in closed form. */
  private def checkBatch(
    p: AccelParams,
    cells: Seq[Seq[Box]],
    out: BatchOutcome,
    consumerNeverStalls: Boolean,
    splits: Seq[Int] = Nil
  ): Unit = {
    val cellSplits = cells.indices.map(splits.lift(_).getOrElse(0))
    val tagSpace = 1 << p.cellTagWidth
    out.error shouldBe AccelError.code(AccelError.None)
    out.cellsDone shouldBe cells.length.toLong
    // Tags arrive in cell order (modulo the tag width): the host can number the cells back.
    var cell = 0
    val numbered = out.pairs.map { case (tag, i, j) =>
      while (cell < cells.length && cell % tagSpace != tag) cell += 1
      withClue(s"beat tagged $tag after cell ${cell - 1}: ") { cell should be < cells.length }
      (cell, i, j)
    }
    numbered.distinct.length shouldBe numbered.length
    for ((boxes, k) <- cells.zipWithIndex) withClue(s"cell $k (n=${boxes.length}): ") {
      numbered.filter(_._1 == k).map { case (_, i, j) => (i, j) }.toSet shouldBe Box.bruteForcePairs(boxes, cellSplits(k))
    }
    out.hits shouldBe out.pairs.length.toLong
    val sizes = cells.map(_.length.toLong)
    val (perBatch, perCells) = frontEndCycles(cells.length)
    out.issueCycles shouldBe sizes.zip(cellSplits).map { case (n, split) => Schedule.issueCycles(n, p.m, split) }.sum
    // Without overlap: one box a cycle, then the cell's start, whatever the consumer does.
    if (!p.overlapsLoads) out.loadCycles shouldBe perBatch + sizes.map(_ + 1).sum
    out.cycles shouldBe out.issueCycles + out.stallCycles + sizes.map(p.fixedCycles).sum + perCells
    // Every cycle of the batch is counted once, as load time or as run time.
    (out.loadCycles + out.cycles) shouldBe out.driverCycles
    if (consumerNeverStalls) {
      out.stallCycles shouldBe 0
      val timeline = BatchTimelineModel(p, cells.map(_.length), cellSplits)
      withClue("against the golden timeline: ") {
        (out.loadCycles, out.cycles) shouldBe ((timeline.load, timeline.run))
      }
    }
  }

  /** The device of `p` with a driver whose inputs start idle. */
  private def withDriver(p: AccelParams)(body: (BroadPhaseAccel, AccelDriver) => Unit): Unit =
    onVerilator(p) { dut =>
      val drv = new AccelDriver(dut)
      drv.idleInputs()
      body(dut, drv)
    }

  private val configurations = Seq(
    SharedConfigs.seedM1,
    SharedConfigs.seedM3,
    SharedConfigs.seedM8,
    SharedConfigs.streamM3,
    SharedConfigs.streamM8,
    AccelParams(m = 2, capacity = 10, arch = Arch.Stream, batchCells = 1), // the head register is the whole queue
    // Loads and runs overlap in a batch: the block RAM's read and write ports must never collide.
    AccelParams(m = 3, capacity = 24, batchCells = 8, memoryStyle = MemoryStyle.Ecp5OutputRegister, arch = Arch.Seed),
    AccelParams(m = 3, capacity = 25, arch = Arch.Stream, batchCells = 8, memoryStyle = MemoryStyle.Ecp5OutputRegister)
  )

  /** The configuration's name in a test's title. */
  private def named(p: AccelParams): String =
    s"m=${p.m}, ${p.arch.name}" + (if (p.memoryStyle != MemoryStyle.Inferred) s", memories ${p.memoryStyle.name}" else "")

  behavior of "A batch"

  for (p <- configurations)
    it should s"give each cell exactly its golden pairs, tagged with it, under back-pressure (${named(p)})" in {
      withDriver(p) { (dut, drv) =>
        val rng       = new Random(7 * p.m + p.arch.id)
        var sawStalls = false
        for {
          round            <- 0 until 4
          (pattern, ready) <- readyPatterns(rng.nextInt())
        } {
          val sizes = cellSizes(rng, p, 1 + rng.nextInt(p.batchCells))
          val cells = sizes.map(cellBoxes(rng, p, _))
          withClue(s"round $round, cells ${sizes.mkString(",")}, consumer '$pattern': ") {
            val out = drv.batch(cells, ready)
            checkBatch(p, cells, out, consumerNeverStalls = pattern == "always ready")
            sawStalls ||= out.stallCycles > 0
          }
        }
        withClue("no pattern ever back-pressured a batch, so stalls went untested: ") { sawStalls shouldBe true }
      }
    }

  for (p <- Seq(configurations(3), configurations(4), configurations(7)))
    it should s"run bipartite cells among triangular ones, each with exactly its A x B pairs, under back-pressure (${named(p)})" in {
      withDriver(p) { (dut, drv) =>
        val rng = new Random(13 * p.m)
        for {
          round            <- 0 until 3
          (pattern, ready) <- readyPatterns(rng.nextInt())
        } {
          val sizes  = cellSizes(rng, p, 1 + rng.nextInt(p.batchCells))
          val splits = sizes.map(n => if (n >= 2 && rng.nextInt(3) != 0) 1 + rng.nextInt(n - 1) else 0)
          val cells  = sizes.map(cellBoxes(rng, p, _))
          withClue(s"round $round, cells ${sizes.zip(splits).mkString(",")}, consumer '$pattern': ") {
            val out = drv.batch(cells, ready, splits)
            checkBatch(p, cells, out, consumerNeverStalls = pattern == "always ready", splits)
          }
        }
        // The same cells as single runs: the batch costs their runs plus the front end's cycles.
        val sizes  = Seq(p.capacity, p.m + 2, 2, p.capacity)
        val splits = Seq(p.capacity / 2, 1, 1, p.capacity - 1)
        val cells  = sizes.map(cellBoxes(rng, p, _))
        val singles = cells.zip(splits).map { case (c, split) => drv.run(c, split = split) }
        for (((c, split), single) <- cells.zip(splits).zip(singles))
          checkRun(p, c, single, consumerNeverStalls = true, split = split)
        val batch = drv.batch(cells, splits = splits)
        checkBatch(p, cells, batch, consumerNeverStalls = true, splits)
        batch.cycles shouldBe singles.map(_.cycles).sum + frontEndCycles(cells.length)._2
      }
    }

  it should "cost the sum of its cells' single runs plus one cycle per cell and one per batch, without overlap (seed)" in {
      val p = configurations(1)
      withDriver(p) { (dut, drv) =>
        val rng   = new Random(11)
        val cells = (Seq(0, 1, 2, p.m, p.m + 1, p.capacity) ++ cellSizes(rng, p, 2)).map(cellBoxes(rng, p, _))
        val singles = cells.map(drv.run(_))
        val batch   = drv.batch(cells)
        checkBatch(p, cells, batch, consumerNeverStalls = true)
        val (perBatch, perCells) = frontEndCycles(cells.length)
        batch.loadCycles shouldBe singles.map(_.loadCycles).sum + perBatch
        batch.cycles shouldBe singles.map(_.cycles).sum + perCells
        batch.issueCycles shouldBe singles.map(_.issueCycles).sum
        batch.hits shouldBe singles.map(_.hits).sum
        // Single runs still work after a batch, untagged and with their own counters.
        val after = drv.run(cells(4))
        checkRun(p, cells(4), after, consumerNeverStalls = true)
      }
    }

  it should "hide each cell's boxes under the run before it, its runs costing what single runs cost (stream)" in {
    val p = configurations(3)
    withDriver(p) { (dut, drv) =>
      val rng   = new Random(11)
      // Long cells (whose tails overlap), short ones (head only) and every edge between.
      val cells = (Seq(p.capacity, p.capacity, 0, 1, 2, p.m, p.m + 1, p.m + 2, p.capacity, 3 * p.m) ++
        cellSizes(rng, p, 4)).map(cellBoxes(rng, p, _))
      val singles = cells.map(drv.run(_))
      val batch   = drv.batch(cells)
      checkBatch(p, cells, batch, consumerNeverStalls = true)
      val (perBatch, perCells) = frontEndCycles(cells.length)
      batch.cycles shouldBe singles.map(_.cycles).sum + perCells
      batch.issueCycles shouldBe singles.map(_.issueCycles).sum
      batch.hits shouldBe singles.map(_.hits).sum
      // The loads the runs hid: at least the whole second cell, which loads under the first cell's run.
      val serialLoad = singles.map(_.loadCycles).sum + perBatch
      withClue(s"batch load cycles ${batch.loadCycles} against ${serialLoad} in series: ") {
        batch.loadCycles should be < serialLoad - p.capacity
      }
      // Two full cells: the second's boxes, objects 0 .. m included, all load
      // under the first's run, so only the second's start cycle is left.
      val pair = drv.batch(cells.take(2))
      checkBatch(p, cells.take(2), pair, consumerNeverStalls = true)
      pair.loadCycles shouldBe singles.head.loadCycles + frontEndCycles(2)._1 + 1
      val after = drv.run(cells(4))
      checkRun(p, cells(4), after, consumerNeverStalls = true)
    }
  }

  it should "run on when the host pushes more cells than the queue holds, tags counting on modulo the tag width" in {
    val p = configurations(4)
    withDriver(p) { (dut, drv) =>
      val rng   = new Random(3)
      // Every cell has a pair (its last box repeats its first), so tags that wrap still number the cells unambiguously.
      val cells = Seq.fill(2 * p.batchCells + 1) { val b = cellBoxes(rng, p, 1 + rng.nextInt(p.capacity - 1)); b :+ b.head }
      checkBatch(p, cells, drv.batch(cells, c => c % 2 == 0), consumerNeverStalls = false)
    }
  }

  // Each configuration costs a Verilator build: reuse the two above.
  for (p <- Seq(configurations(1), configurations(3)))
    it should s"end a cell over the capacity with LoadOverflow and no beats of it, consuming its boxes, and finish the batch (${p.arch.name})" in {
      withDriver(p) { (dut, drv) =>
        val rng   = new Random(5)
        val cells = Seq(9, p.capacity + 3, 7, 0).map(n => Box.Scenes.uniform(rng, n, p.keyWidth, 30, 10))
        val out   = drv.batch(cells)
        out.error shouldBe AccelError.code(AccelError.LoadOverflow)
        out.cellsDone shouldBe 4
        out.pairs.map(_._1).toSet should not contain 1
        for (k <- Seq(0, 2)) out.pairs.filter(_._1 == k).map(p => (p._2, p._3)).toSet shouldBe Box.bruteForcePairs(cells(k))
        // The error does not outlive the batch: the next batch and run are clean.
        val good = Seq(cells(0), cells(2))
        checkBatch(p, good, drv.batch(good), consumerNeverStalls = true)
        checkRun(p, cells(2), drv.run(cells(2)), consumerNeverStalls = true)
      }
    }

  it should "refuse a start while it is under way, and drop boxes loaded without a start before it" in {
    val p = configurations(1)
    withDriver(p) { (dut, drv) =>
      val rng = new Random(9)
      drv.load(Box.Scenes.uniform(rng, 5, p.keyWidth, 30, 10)) // never started
      dut.io.cells.valid.poke(true.B)
      dut.io.cells.bits.count.poke(6.U)
      dut.io.cells.ready.expect(true.B)
      dut.clock.step()
      dut.io.cells.valid.poke(false.B)
      dut.io.status.batch.expect(true.B)
      dut.io.status.busy.expect(true.B)
      dut.io.status.done.expect(false.B)
      dut.io.status.loaded.expect(0.U)
      dut.io.start.ready.expect(false.B)
      dut.io.load.ready.expect(true.B)
      // The cell's six boxes, then the end of the batch.
      val cell = Box.Scenes.uniform(rng, 6, p.keyWidth, 30, 10)
      drv.load(cell)
      dut.io.load.ready.expect(false.B)
      dut.io.result.ready.poke(true.B)
      val pairs = Seq.newBuilder[(Int, Int)]
      var cycles = 0
      while (dut.io.status.busy.peek().litToBoolean) {
        dut.io.start.ready.expect(false.B)
        if (dut.io.result.valid.peek().litToBoolean) {
          dut.io.result.bits.cell.expect(0.U)
          val mask = dut.io.result.bits.mask.peek().litValue
          pairs ++= AccelDriver.beatPairs(p, dut.io.result.bits.iBase.peek().litValue.toInt,
            dut.io.result.bits.jBase.peek().litValue.toInt, mask)
        }
        dut.clock.step(); cycles += 1
        if (cycles > 1000) fail("the batch did not end")
      }
      pairs.result().toSet shouldBe Box.bruteForcePairs(cell)
      dut.io.status.done.expect(true.B)
      dut.io.status.cellsDone.expect(1.U)
      dut.io.start.ready.expect(true.B)
    }
  }

  it should "fail its timeline check when the front end loads the next cell only after the last one ended (mutant)" in {
    val p = configurations(3).copy(faults = Set(Fault.BatchLoadsInSeries))
    withDriver(p) { (dut, drv) =>
      val rng   = new Random(17)
      val cells = Seq(p.capacity, p.capacity, 2 * p.m).map(cellBoxes(rng, p, _))
      intercept[TestFailedException](checkBatch(p, cells, drv.batch(cells), consumerNeverStalls = true))
    }
  }

  it should "fail when the next cell's objects 0 .. m are written before the start copied the head registers (mutant)" in {
    val p = configurations(3).copy(faults = Set(Fault.HeadCopiedLate))
    withDriver(p) { (dut, drv) =>
      val rng   = new Random(19)
      // Cells of at most m+1 boxes are sent in order: the next one's object 0 comes right after the start.
      val cells = Seq(p.capacity, p.m + 1, p.m, 2).map(cellBoxes(rng, p, _))
      // The engine's own check stops the simulation; were it absent, the pairs would be wrong.
      intercept[chiseltest.ChiselAssertionError](checkBatch(p, cells, drv.batch(cells), consumerNeverStalls = true))
    }
  }

  it should "fail its check when the front end's cell counter skips short cells (mutant)" in {
    val p = AccelParams(m = 3, capacity = 12, batchCells = 8, faults = Set(Fault.CellCounterSkipsShortCells), arch = Arch.Seed)
    withDriver(p) { (dut, drv) =>
      val rng   = new Random(13)
      val cells = Seq(5, 1, 8, 0, 12).map(n => Box.Scenes.uniform(rng, n, p.keyWidth, 20, 10))
      val out   = drv.batch(cells)
      intercept[TestFailedException](checkBatch(p, cells, out, consumerNeverStalls = true))
    }
  }
}
