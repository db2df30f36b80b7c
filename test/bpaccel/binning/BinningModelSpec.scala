package bpaccel.binning

import scala.util.Random

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import bpaccel.Box

/** The golden model alone: binning, the exactly-once rule against brute
  * force, errors, and the cycle model's own consistency (its pairs are the
  * function model's; its schedule is the stream schedule's; its phases follow
  * the closed forms where they apply).
  */
class BinningModelSpec extends AnyFlatSpec with Matchers {

  /** Small configurations: every group shape up to G = 16, one to four lanes, narrow keys. */
  private val configs: Seq[BinningParams] =
    for {
      gb <- Seq(Seq(1, 1, 1), Seq(2, 1, 1), Seq(1, 2, 1), Seq(1, 1, 2), Seq(2, 2, 1))
      g  <- Seq(1, 2, 3, 4)
    } yield BinningParams(groupBits = gb, lanesPerGroup = g, keyWidth = 7, cellBits = 3, boxCapacity = 256,
      groupCapacity = 256, intakeBoxes = 1 + (g % 3), pairsPerBeat = 2, memoryOutputStages = g % 2)

  private def counts[T](xs: Seq[T]): Map[T, Int] = xs.groupMapReduce(identity)(_ => 1)(_ + _)

  "The binning model" should "report every overlapping pair exactly once, against brute force" in {
    val rng = new Random(41)
    var frames = 0
    for (p <- configs; round <- 0 until 6) {
      val (shift, dims) = BinScenes.grid(rng, p)
      val n = Seq(0, 1, 2, 3, rng.nextInt(20), rng.nextInt(80))(round)
      for ((name, boxes) <- BinScenes.all(rng, n, shift, dims)) withClue(s"$name, $p, shift $shift, dims $dims, n $n: ") {
        val f = BinFrame(boxes, shift, dims)
        val reported = BinningModel.reportedPairs(p, f)
        counts(reported).values.forall(_ == 1) shouldBe true
        reported.toSet shouldBe Box.bruteForcePairs(boxes)
        reported.foreach { case (i, j) => i should be < j }
        frames += 1
      }
    }
    info(s"$frames frames")
  }

  it should "put each box's entries one per group, into the cells it covers, in stream order" in {
    val rng = new Random(42)
    for (p <- configs.take(8)) {
      val (shift, dims) = BinScenes.grid(rng, p)
      val boxes = BinScenes.straddling(rng, 40, shift, dims) ++ BinScenes.uniform(rng, 40, shift, dims)
      val f = BinFrame(boxes, shift, dims)
      val binned = BinningModel.bin(p, f)
      binned.ok shouldBe true
      for ((es, gr) <- binned.groups.zipWithIndex) {
        es.map(_.box) shouldBe es.map(_.box).sorted.distinct // one per box, in order
        es.foreach(e => p.groupOf(e.cell) shouldBe gr)
      }
      for ((b, i) <- boxes.zipWithIndex)
        binned.groups.flatten.filter(_.box == i).map(_.cell).toSet shouldBe BinningModel.cellsOf(b, shift).toSet
    }
  }

  it should "number a group's local cells so that each cell of the grid has its own (group, local cell)" in {
    for (p <- configs.take(5)) {
      val all = for (x <- 0 until 8; y <- 0 until 8; z <- 0 until 8) yield Seq(x, y, z)
      all.map(c => (p.groupOf(c), p.localCellOf(c))).distinct.length shouldBe all.length
      all.map(p.localCellOf).max should be < p.localCells
    }
  }

  it should "name each frame error and its first box" in {
    val p = BinningParams(groupBits = Seq(1, 1, 1), lanesPerGroup = 2, keyWidth = 6, cellBits = 2, boxCapacity = 16,
      groupCapacity = 3, intakeBoxes = 2, pairsPerBeat = 2)
    val ok = Box(Seq(BigInt(0), BigInt(0), BigInt(0)), Seq(BigInt(3), BigInt(3), BigInt(3)))
    def at(k: Int, b: Box) = Seq.tabulate(5)(i => if (i == k) b else ok)
    def keys(lo: Int, hi: Int, axis: Int) = ok.copy(min = ok.min.updated(axis, BigInt(lo)), max = ok.max.updated(axis, BigInt(hi)))
    val cases: Seq[(String, BinFrame, Int, Long)] = Seq(
      ("n above capacity", BinFrame(Seq(ok), 3, Seq(4, 4, 4), header = Some(17)), BinningErrorCode.CountOverCapacity, 0),
      ("shift above localBits", BinFrame(Seq(ok), 5, Seq(1, 1, 1)), BinningErrorCode.BadGrid, 0),
      ("a dimension of 0", BinFrame(Seq(ok), 3, Seq(1, 0, 1)), BinningErrorCode.BadGrid, 0),
      ("a dimension above 2^cellBits", BinFrame(Seq(ok), 3, Seq(1, 1, 5)), BinningErrorCode.BadGrid, 0),
      ("a key past the grid", BinFrame(at(3, keys(2, 40, 1)), 3, Seq(4, 4, 4)), BinningErrorCode.KeyOutOfGrid, 3),
      ("a box three cells wide", BinFrame(at(2, keys(7, 16, 2)), 3, Seq(4, 4, 4)), BinningErrorCode.BoxSpansCells, 2),
      ("an inverted box", BinFrame(at(2, keys(5, 4, 0)), 3, Seq(4, 4, 4)), BinningErrorCode.BoxInverted, 2),
      ("a fourth entry in group 0", BinFrame(Seq.fill(5)(ok), 3, Seq(4, 4, 4)), BinningErrorCode.GroupOverflow, 3),
      ("fewer boxes than n", BinFrame(Seq(ok, ok), 3, Seq(4, 4, 4), header = Some(3)), BinningErrorCode.LengthMismatch, 2),
      ("more boxes than n", BinFrame(Seq(ok, ok, ok), 3, Seq(4, 4, 4), header = Some(1)), BinningErrorCode.LengthMismatch, 1),
      ("the first of two errors", BinFrame(Seq(ok, keys(5, 4, 0), keys(2, 40, 1)), 3, Seq(4, 4, 4)), BinningErrorCode.BoxInverted, 1)
    )
    for ((name, f, code, detail) <- cases) withClue(s"$name: ") {
      val b = BinningModel.bin(p, f)
      BinningErrorCode.name(b.error) shouldBe BinningErrorCode.name(code)
      b.detail shouldBe detail
    }
  }

  "The cycle model" should "send exactly the function model's pairs, each once, under any ready pattern" in {
    val rng = new Random(43)
    for (p <- configs; round <- 0 until 2) {
      val (shift, dims) = BinScenes.grid(rng, p)
      val f = BinFrame(BinScenes.all(rng, rng.nextInt(60), shift, dims)(rng.nextInt(5))._2, shift, dims)
      val patterns: Seq[Long => Boolean] = Seq(_ => true, t => t % 3 == 0, _ => rng.nextInt(4) == 0)
      for (ready <- patterns) withClue(s"$p $f: ") {
        val r = BinningCycleModel.run(p, f, ready, offer = _ => rng.nextInt(3) != 0)
        r.error shouldBe BinningErrorCode.None
        r.pairs.sorted shouldBe BinningModel.reportedPairs(p, f).sorted
        r.beats.foreach(b => b.pairs.length should (be >= 1 and be <= p.pairsPerBeat))
        r.boxesReceived shouldBe f.boxes.length.toLong
      }
    }
  }

  it should "run each group's schedule cycles in order, one cell after another with one bubble each" in {
    val rng = new Random(44)
    for (p <- configs) {
      val (shift, dims) = BinScenes.grid(rng, p)
      val f = BinFrame(BinScenes.oneCell(rng, 30, shift, dims) ++ BinScenes.uniform(rng, 30, shift, dims), shift, dims)
      val r = BinningCycleModel.run(p, f)
      val binned = BinningModel.bin(p, f)
      for (gr <- 0 until p.groups) {
        val cells = BinningModel.groupCells(p, f, binned, gr).map(_._2.length).filter(_ >= 2)
        r.ops(gr).map(_.op) shouldBe BinningModel.groupOps(p, f, binned, gr)
        r.ops(gr).length.toLong shouldBe cells.map(n => 1 + BinningModel.issueCycles(n, p.g)).sum
        r.ops(gr).map(_.cycle).sliding(2).foreach { case Seq(a, b) => b should be > a; case _ => }
      }
    }
  }

  it should "follow the closed forms of each phase (prefix Lc, sort E + le + 1, first schedule cycle, back-to-back cells)" in {
    val rng = new Random(45)
    for (p <- configs) {
      val shift = p.maxShift
      val dims  = Seq.fill(3)(1 << p.cellBits)
      val cell  = 1 << shift
      // Two cells of group 0 first in its walk, (0,0,0) and (2^ax,0,0), with points that never overlap
      // (no hit, so no credit stall), and random boxes elsewhere.
      def points(x0: Int, k: Int) = Seq.tabulate(k)(i => bpaccel.Box(Seq(BigInt(x0 + i % cell), BigInt(i / cell), BigInt(0)),
        Seq(BigInt(x0 + i % cell), BigInt(i / cell), BigInt(0))))
      val (n0, n1) = (2 + rng.nextInt(9), 2 + rng.nextInt(9))
      val f = BinFrame(points(0, n0) ++ points((1 << p.groupBits(0)) * cell, n1), shift, dims)
      val r  = BinningCycleModel.run(p, f)
      val ph = r.phases.get
      val lc = p.localDims(dims).product
      val le = p.memoryReadLatency
      val binned = BinningModel.bin(p, f)
      for (gr <- 0 until p.groups) withClue(s"$p group $gr: ") {
        ph.sort(gr) shouldBe ph.prefix + lc
        ph.compute(gr) shouldBe ph.sort(gr) + binned.groups(gr).length + le + 1
      }
      withClue(s"$p, cells of $n0 and $n1: ") {
        // walker read C0, queued C0+1, reader's first read C0+2, 2*le through both memories, a cycle
        // into the item queue and one into the window, min(n, g) items (all it compares): the first cell's bubble.
        val ops = r.ops(0).map(_.cycle)
        ops.head shouldBe ph.compute(0) + 3 + 2 * le + n0.min(p.g)
        // Cells back to back, one bubble each: 1 + C(n, g) cycles a cell, no gap.
        ops shouldBe (ops.head until ops.head + 2 + BinningModel.issueCycles(n0, p.g) + BinningModel.issueCycles(n1, p.g))
        // The group is done three cycles after its last schedule cycle (its hits in flight), but not
        // before its walker has read and cleared every cell of the walk (one a cycle from C0, never
        // waiting here: the cell queue holds both cells).
        ph.groupDone(0) shouldBe (ops.last + 3).max(ph.compute(0) + lc + 1)
      }
    }
  }

  it should "end a frame with an error after the intake and a clear of every cell table row" in {
    val p = configs.head
    val ok = Box(Seq.fill(3)(BigInt(1)), Seq.fill(3)(BigInt(2)))
    val f = BinFrame(Seq(ok, ok, ok.copy(max = Seq(BigInt(200), BigInt(2), BigInt(2)))), 4, Seq(2, 2, 2))
    val r = BinningCycleModel.run(p, f)
    r.error shouldBe BinningErrorCode.KeyOutOfGrid
    r.detail shouldBe 2
    r.beats shouldBe empty
    r.summaryCycle shouldBe r.intakeDone + p.localCells + 1
  }
}
