package bpaccel.binning

import scala.util.Random

import org.scalatest.flatspec.AnyFlatSpec

import bpaccel.{Box, MemoryStyle}

/** The core on Verilator against the cycle model, event by event (entry
  * writes, each group's schedule cycles with their lanes, every output beat
  * and its cycle, the summary's cycle and counters), and its pairs against
  * brute force: many frames per compiled configuration.
  */
class BinningHardwareSpec extends AnyFlatSpec with BinningSimulators with BinningChecks {

  /** G = 8, two lanes, two boxes a cycle, two pairs a beat, one memory output register. */
  val small = BinningParams(groupBits = Seq(1, 1, 1), lanesPerGroup = 2, keyWidth = 7, cellBits = 3, boxCapacity = 128,
    groupCapacity = 48, intakeBoxes = 2, pairsPerBeat = 2, memoryOutputStages = 1, hitQueueDepth = 4, debugPort = true)

  /** G = 16 of an uneven shape, three lanes, three boxes a cycle, three pairs a beat (uneven clusters),
    * memories with their first output register in the block RAM and two stages.
    */
  val odd = BinningParams(groupBits = Seq(1, 2, 1), lanesPerGroup = 3, keyWidth = 9, cellBits = 3, boxCapacity = 200,
    groupCapacity = 64, intakeBoxes = 3, pairsPerBeat = 3, memoryOutputStages = 2, memoryStyle = MemoryStyle.Ecp5OutputRegister,
    laneQueueDepth = 1, maskQueueDepth = 2, cellQueueDepth = 2, hitQueueDepth = 3, debugPort = true)

  private def runBoth(p: BinningParams, d: BinningDriver, f: BinFrame, ready: Long => Boolean = _ => true,
                      offer: Long => Boolean = _ => true, layout: Option[Seq[Int]] = None): FrameOutcome = {
    val model = BinningCycleModel.run(p, f, ready, offer, layout)
    val out = d.run(f, ready, offer, layout).get
    checkAgainstModel(p, out, model, debug = true)
    if (model.error == BinningErrorCode.None) checkPairs(f, out) else out.beats shouldBe empty
    out
  }

  /** Random frames of every scene kind and size, on random grids. */
  private def frames(p: BinningParams, rng: Random, rounds: Int, sizes: Seq[Int]): Seq[(String, BinFrame)] =
    for {
      round <- 0 until rounds
      (shift, dims) = BinScenes.grid(rng, p)
      n = sizes(round % sizes.length)
      (name, boxes) <- BinScenes.all(rng, n, shift, dims)
    } yield (s"$name, shift $shift, dims $dims, n $n", BinFrame(boxes, shift, dims))

  /** A consumer pattern: always, periodic, random, or long stalls. */
  private def readyPattern(rng: Random, kind: Int): Long => Boolean = kind match {
    case 0 => _ => true
    case 1 => t => t % 3 == 1
    case 2 => val r = new Random(rng.nextLong()); val bits = Array.fill(4096)(r.nextInt(10) < 4); t => bits((t % 4096).toInt)
    case _ => t => (t / 37) % 2 == 1
  }

  private def randomLayout(rng: Random, boxes: Int, w: Int): Seq[Int] = {
    val sizes = Seq.newBuilder[Int]
    var left = boxes
    while (left > 0) { val s = rng.nextInt(w + 1).min(left); sizes += s; left -= s }
    sizes += 0 // a last beat without boxes
    sizes.result()
  }

  behavior of "The binning core"

  it should "match the cycle model event by event and report each pair once (G = 8, g = 2)" in {
    onVerilator(small) { (_, d) =>
      val rng = new Random(7)
      var errors = 0
      val all = frames(small, rng, 30, Seq(0, 1, 2, 3, 5, 17, 40, 90))
      for ((name, f) <- all) withClue(s"$name: ") {
        if (runBoth(small, d, f).error != BinningErrorCode.None) errors += 1
      }
      info(s"${all.length} frames ($errors of them GROUP_OVERFLOW)")
    }
  }

  it should "keep every pair, beat and counter under random consumers, host pauses and beat layouts" in {
    onVerilator(small) { (_, d) =>
      val rng = new Random(8)
      val all = frames(small, rng, 8, Seq(12, 30, 60, 4))
      for (((name, f), k) <- all.zipWithIndex) withClue(s"$name, consumer $k: ") {
        val offerBits = Array.fill(512)(rng.nextInt(3) != 0)
        runBoth(small, d, f, readyPattern(rng, k % 4), t => offerBits((t % 512).toInt),
          Option.when(k % 2 == 1)(randomLayout(rng, f.boxes.length, small.intakeBoxes)))
      }
      info(s"${all.length} frames")
    }
  }

  it should "end each kind of bad frame with its error and first box, send no pair, and then run the next frame" in {
    onVerilator(small) { (_, d) =>
      val rng = new Random(9)
      val ok = Box(Seq.fill(3)(BigInt(2)), Seq.fill(3)(BigInt(5)))
      def boxes(n: Int) = BinScenes.uniform(rng, n, 4, Seq(4, 4, 4))
      def broken(at: Int, axis: Int, lo: Int, hi: Int) =
        boxes(9).updated(at, ok.copy(min = ok.min.updated(axis, BigInt(lo)), max = ok.max.updated(axis, BigInt(hi))))
      val bad: Seq[(String, BinFrame, Int, Long)] = Seq(
        ("n above the capacity", BinFrame(boxes(3), 4, Seq(4, 4, 4), header = Some(129)), BinningErrorCode.CountOverCapacity, 0),
        ("a shift above localBits", BinFrame(boxes(3), 5, Seq(1, 1, 1)), BinningErrorCode.BadGrid, 0),
        ("a dimension of 0", BinFrame(boxes(3), 4, Seq(4, 0, 4)), BinningErrorCode.BadGrid, 0),
        ("a dimension above 2^cellBits", BinFrame(boxes(3), 4, Seq(9, 4, 4)), BinningErrorCode.BadGrid, 0),
        ("a key past the grid", BinFrame(broken(6, 2, 3, 64), 4, Seq(4, 4, 4)), BinningErrorCode.KeyOutOfGrid, 6),
        ("a box three cells wide", BinFrame(broken(5, 1, 3, 33), 4, Seq(4, 4, 4)), BinningErrorCode.BoxSpansCells, 5),
        ("an inverted box", BinFrame(broken(0, 0, 9, 8), 4, Seq(4, 4, 4)), BinningErrorCode.BoxInverted, 0),
        ("49 boxes in one group", BinFrame(Seq.fill(60)(ok), 4, Seq(4, 4, 4)), BinningErrorCode.GroupOverflow, 48),
        ("fewer boxes than n", BinFrame(boxes(7), 4, Seq(4, 4, 4), header = Some(10)), BinningErrorCode.LengthMismatch, 7),
        ("more boxes than n", BinFrame(boxes(7), 4, Seq(4, 4, 4), header = Some(3)), BinningErrorCode.LengthMismatch, 3),
        ("boxes after n = 0", BinFrame(boxes(2), 4, Seq(4, 4, 4), header = Some(0)), BinningErrorCode.LengthMismatch, 0),
        ("two errors: the first counts", BinFrame(broken(8, 0, 9, 8).updated(3, ok.copy(max = Seq(BigInt(99), BigInt(5), BigInt(5)))),
          4, Seq(4, 4, 4)), BinningErrorCode.KeyOutOfGrid, 3)
      )
      val good = BinFrame(boxes(40), 4, Seq(4, 4, 4))
      for ((name, f, code, detail) <- bad) withClue(s"$name: ") {
        val out = runBoth(small, d, f)
        BinningErrorCode.name(out.error) shouldBe BinningErrorCode.name(code)
        out.detail shouldBe detail
        runBoth(small, d, good) // the tables were cleared: the next frame is exact
      }
    }
  }

  it should "return to idle at an abort in any phase, clear its tables, and run the next frame exactly" in {
    onVerilator(small) { (_, d) =>
      val rng = new Random(10)
      val (shift, dims) = (4, Seq(3, 4, 2))
      for (k <- 0 until 14) {
        val f = BinFrame(BinScenes.straddling(rng, 30, shift, dims), shift, dims)
        val length = BinningCycleModel.run(small, f, readyPattern(rng, 1)).summaryCycle
        val at = if (k == 0) 0L else if (k == 1) length else rng.nextLong(length)
        withClue(s"abort in cycle $at of $length: ") {
          d.run(f, readyPattern(rng, 1), abortAt = Some(at)) shouldBe None
          d.waitReady() shouldBe small.localCells // the clear after the abort, then idle
          runBoth(small, d, BinFrame(BinScenes.uniform(rng, 25, shift, dims), shift, dims))
        }
      }
    }
  }

  it should "match the cycle model on an uneven configuration (G = 16, g = 3, w = 3, P = 3, block-RAM output registers)" in {
    onVerilator(odd) { (_, d) =>
      val rng = new Random(11)
      val all = frames(odd, rng, 12, Seq(2, 7, 33, 80))
      for (((name, f), k) <- all.zipWithIndex) withClue(s"$name: ") {
        runBoth(odd, d, f, readyPattern(rng, k % 4), if (k % 3 == 0) (t => t % 4 != 0) else (_ => true))
      }
      info(s"${all.length} frames")
    }
  }
}
