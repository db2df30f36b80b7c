package bpaccel.shell

import scala.util.Random

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import bpaccel.{Box, Simulators}
import bpaccel.binning.{BinFrame, BinningCycleModel, BinningErrorCode, BinningModel, BinScenes}

/** The binning device behind the AXI shell: FRAME commands through s_axis,
  * replies from m_axis, on Verilator (one clock, one model for every test).
  * Pairs against the binning golden model and brute force, each exactly
  * once; the trailer's counters; every FRAME error with its code and detail,
  * and the next command answered right after it.
  */
class FrameShellSpec extends AnyFlatSpec with Simulators with Matchers {
  val binning = ShellConfigs.binningG8
  val p = ShellParams(binning, streamBits = 128, dualClock = false)

  private def onShell(seed: Long)(body: ShellDriver => Unit): Unit =
    onSharedVerilator("BinningShell", p)(new ShellHarness(p)) { dut => body(new ShellDriver(dut, new Random(seed))) }

  private def frameWords(f: BinFrame): Seq[Long] = FrameWords.frame(p, f.boxes, f.shift, f.dims, Some(f.n.toLong))
  private def code(name: String): Long = Protocol.errors.find(_.name == name).get.code.toLong

  /** A reply that must hold exactly the frame's pairs, with the trailer's counters right. */
  def checkFrame(f: BinFrame, r: ShellReply): Unit = {
    r.magic shouldBe Protocol.TrailerMagic
    r.opcode shouldBe Protocol.Frame.code
    withClue(s"error ${r.error}, detail ${r.detail}: ") { r.error shouldBe 0 }
    r.detail shouldBe 0
    val pairs = r.framePairs(p.indexWords)
    pairs.foreach { case (i, j) => withClue(s"pair ($i, $j): ") { i should be < j; j should be < f.n } }
    pairs.distinct.length shouldBe pairs.length
    pairs.sorted shouldBe BinningModel.reportedPairs(binning, f).sorted
    pairs.toSet shouldBe Box.bruteForcePairs(f.boxes)
    r.body.length shouldBe (r.records * p.indexWords + p.wordsPerBeat - 1) / p.wordsPerBeat * p.wordsPerBeat
    r.body.drop(r.records.toInt * p.indexWords).foreach(_ shouldBe 0)
    r.records shouldBe pairs.length
    r.pairs shouldBe pairs.length
    r.boxes shouldBe f.n
    r.cells shouldBe 0
    val binned = BinningModel.bin(binning, f)
    r.issueCycles shouldBe (0 until binning.groups).map(gr => BinningModel.groupOps(binning, f, binned, gr).count(!_.bubble)).sum
    r.intakeCycles should be > 0L
    r.deviceCycles should be > r.intakeCycles
  }

  /** A reply that carries an error and no records. */
  def checkError(r: ShellReply, name: String, detail: Long, opcode: Int = Protocol.Frame.code): Unit = {
    r.magic shouldBe Protocol.TrailerMagic
    r.opcode shouldBe opcode
    withClue(s"error ${r.error}, detail ${r.detail}: ") {
      r.error shouldBe code(name)
      r.detail shouldBe detail
    }
    r.records shouldBe 0
    r.body shouldBe empty
  }

  /** The golden model's error for a frame, by the protocol's name. */
  private def modelError(f: BinFrame): (String, Long) = {
    val b = BinningModel.bin(binning, f)
    (BinningErrorCode.name(b.error), b.detail)
  }

  private def frames(rng: Random, sizes: Seq[Int]): Seq[(String, BinFrame)] =
    for {
      n <- sizes
      (shift, dims) = BinScenes.grid(rng, binning)
      (name, boxes) <- BinScenes.all(rng, n, shift, dims)
    } yield (s"$name, shift $shift, dims $dims, n $n", BinFrame(boxes, shift, dims))

  "The binning shell" should "tell its architecture, lane groups, cell bits and opcodes through its registers" in {
    onShell(1) { d =>
      val map = ShellRegisters(p)
      d.read(map("ARCH").offset) shouldBe 2
      d.read(map("OPCODES").offset) shouldBe (1 << Protocol.Frame.code)
      d.read(map("LANE_GROUPS").offset) shouldBe 8
      d.read(map("LANES_PER_GROUP").offset) shouldBe 2
      d.read(map("CELL_BITS").offset) shouldBe 3
      d.read(map("CAPACITY").offset) shouldBe 64
      d.read(map("INTAKE_BOXES").offset) shouldBe 4
    }
  }

  it should "return every overlapping pair once for random frames, under random input gaps and output stalls" in {
    val rng = new Random(11)
    val all = frames(rng, Seq(0, 1, 2, 3, 5, 9, 13, 17, 24, 31, 40))
    onShell(2) { d =>
      for ((batch, round) <- all.grouped(5).zipWithIndex) {
        val (inGap, outStall) = Seq((0.0, 0.0), (0.3, 0.5), (0.6, 0.2), (0.1, 0.8))(round % 4)
        val replies = d.exchange(batch.map(x => frameWords(x._2)), inGap, outStall)
        for (((name, f), r) <- batch.zip(replies)) withClue(s"$name, gaps $inGap, stalls $outStall: ")(checkFrame(f, r))
      }
    }
  }

  it should "name each FRAME error's first offending box, and answer the next command right" in {
    val rng = new Random(5)
    val (shift, dims) = (4, Seq(3, 2, 4))
    def good(n: Int) = BinFrame(BinScenes.uniform(rng, n, shift, dims), shift, dims)
    def key(cell: Int, offset: Int) = BigInt((cell << shift) + offset)
    def boxAt(cells: Seq[Int]) = Box(cells.map(key(_, 1)), cells.map(key(_, 9)))
    val legal = good(12)
    def withBox(at: Int, b: Box) = legal.copy(boxes = legal.boxes.updated(at, b))
    val outside   = withBox(6, Box(Seq(key(0, 0), key(0, 0), key(3, 2)), Seq(key(0, 5), key(0, 5), key(4, 1))))
    val spans     = withBox(9, Box(Seq(key(0, 3), key(0, 0), key(0, 0)), Seq(key(2, 0), key(0, 5), key(0, 5))))
    val inverted  = withBox(3, Box(Seq(key(1, 5), key(0, 0), key(0, 0)), Seq(key(1, 4), key(0, 5), key(0, 5))))
    val crowded   = BinFrame(Seq.fill(50)(boxAt(Seq(1, 1, 1))), shift, dims)
    val overCap   = BinFrame(legal.boxes.take(3), shift, dims, header = Some(65))
    val badShift  = legal.copy(shift = binning.maxShift + 1)
    val badDims   = legal.copy(dims = Seq(3, 0, 4))
    val tooLong   = legal.copy(header = Some(5))
    val cases: Seq[(String, BinFrame)] = Seq(
      "a key out of the grid" -> outside, "a box over three cells" -> spans, "an inverted box" -> inverted,
      "a full group" -> crowded, "n above the capacity" -> overCap, "a shift above MAX_SHIFT" -> badShift,
      "a dimension of 0" -> badDims, "boxes after the n-th" -> tooLong,
      "a key out of the grid and boxes after the n-th" -> withBox(2, outside.boxes(6)).copy(header = Some(4))
    )
    onShell(3) { d =>
      for ((name, f) <- cases) withClue(s"$name: ") {
        val (expected, detail) = modelError(f)
        expected should not be "NONE"
        val next = good(20)
        val Seq(bad, after) = d.exchange(Seq(frameWords(f), frameWords(next)), inGap = 0.2, outStall = 0.3)
        checkError(bad, expected, detail)
        checkFrame(next, after)
      }
    }
  }

  it should "report a packet cut short as LENGTH_MISMATCH naming the boxes it carried, unless a box before the cut erred" in {
    val rng = new Random(6)
    val (shift, dims) = (3, Seq(4, 4, 2))
    val boxes = BinScenes.uniform(rng, 12, shift, dims)
    val outside = Box(Seq(0, 0, 0).map(BigInt(_)), Seq(BigInt(0), BigInt(4 << shift), BigInt(0)))
    val wide = Box(Seq(0, 0, 0).map(BigInt(_)), Seq(BigInt(1), BigInt(1), BigInt(1) << binning.keyWidth))
    // 4 + 3m words padded to beats of 4: m = 7 leaves 3 zero words, which read as one more box.
    val cases = Seq(0, 1, 5, 6, 7, 8).map(m => (s"$m boxes of 12", boxes.take(m), if (m == 7) 8L else m.toLong, "LENGTH_MISMATCH")) ++ Seq(
      ("6 boxes of 12, box 2 out of the grid", boxes.take(6).updated(2, outside), 2L, "KEY_OUT_OF_GRID"),
      ("5 boxes of 12, box 4 too wide (the cut's beat)", boxes.take(5).updated(4, wide), 4L, "KEY_TOO_WIDE"),
      ("9 boxes of 12, box 8 too wide and box 1 out of the grid", boxes.take(9).updated(8, wide).updated(1, outside), 1L, "KEY_OUT_OF_GRID")
    )
    onShell(4) { d =>
      for ((name, sent, detail, expected) <- cases) withClue(s"$name: ") {
        val next = BinFrame(boxes.take(9), shift, dims)
        val Seq(bad, after) = d.exchange(Seq(FrameWords.frame(p, sent, shift, dims, n = Some(12)), frameWords(next)),
          inGap = 0.3, outStall = 0.3)
        checkError(bad, expected, detail)
        checkFrame(next, after)
      }
      // A header cut short: TLAST inside it.
      val Seq(cut, after) = d.exchange(Seq(Seq(FrameWords.header(Protocol.Frame.code), 3L), frameWords(BinFrame(boxes, shift, dims))))
      checkError(cut, "LENGTH_MISMATCH", 0)
      checkFrame(BinFrame(boxes, shift, dims), after)
    }
  }

  it should "report a key wider than KEY_WIDTH as KEY_TOO_WIDE unless an earlier box erred first" in {
    val rng = new Random(7)
    val (shift, dims) = (5, Seq(2, 3, 2))
    val legal = BinScenes.uniform(rng, 14, shift, dims)
    val wide = Box(Seq(BigInt(1) << binning.keyWidth, BigInt(0), BigInt(0)), Seq(BigInt(3), BigInt(5), BigInt(5)))
    val outside = Box(Seq(0, 0, 0).map(BigInt(_)), Seq(BigInt(2 << shift), BigInt(0), BigInt(0)))
    val cases = Seq(
      ("alone", legal.updated(9, wide), "KEY_TOO_WIDE", 9L),
      ("after a box out of the grid in the same beat", legal.updated(4, outside).updated(5, wide), "KEY_OUT_OF_GRID", 4L),
      ("before a box out of the grid", legal.updated(2, wide).updated(3, outside), "KEY_TOO_WIDE", 2L),
      ("in the last beat's top key", legal.updated(13, Box(Seq(0, 0, 0).map(BigInt(_)), Seq(BigInt(1), BigInt(1), BigInt(0xf000)))),
        "KEY_TOO_WIDE", 13L)
    )
    onShell(5) { d =>
      for ((name, boxes, expected, detail) <- cases) withClue(s"$name: ") {
        val next = BinFrame(legal, shift, dims)
        val Seq(bad, after) = d.exchange(Seq(FrameWords.frame(p, boxes, shift, dims), frameWords(next)), inGap = 0.2)
        checkError(bad, expected, detail)
        checkFrame(next, after)
      }
    }
  }

  it should "report reserved header bits as BAD_GRID, and a CELLS command as BAD_COMMAND" in {
    val rng = new Random(8)
    val (shift, dims) = (2, Seq(4, 4, 4))
    val f = BinFrame(BinScenes.uniform(rng, 10, shift, dims), shift, dims)
    val cells = Seq(FrameWords.header(Protocol.Cells.code), 1L, 2L, 0L) ++ f.boxes.take(2).flatMap(FrameWords.box(p, _))
    onShell(6) { d =>
      val replies = d.exchange(Seq(
        FrameWords.frame(p, f.boxes, shift | 1 << 8, dims), frameWords(f),
        FrameWords.frame(p, f.boxes, shift, dims, dimsHigh = 1), frameWords(f),
        cells, frameWords(f)
      ), inGap = 0.1, outStall = 0.1)
      checkError(replies(0), "BAD_GRID", 0)
      checkError(replies(2), "BAD_GRID", 0)
      checkError(replies(4), "BAD_COMMAND", 0, opcode = Protocol.Cells.code)
      Seq(1, 3, 5).foreach(i => checkFrame(f, replies(i)))
    }
  }

  it should "end a frame on CONTROL.ABORT with ABORTED, drain its packet, and answer the next frame" in {
    val rng = new Random(9)
    val (shift, dims) = (3, Seq(2, 2, 2))
    val f = BinFrame(BinScenes.oneCell(rng, 40, shift, dims), shift, dims)
    onShell(7) { d =>
      // The input stops after 5 beats; the abort comes while it waits; the rest of the packet follows.
      val Seq(aborted, after) = d.exchange(Seq(frameWords(f), frameWords(f)), hold = Some((5, 400L)), abortAt = Some(200L))
      aborted.error shouldBe code("ABORTED")
      aborted.opcode shouldBe Protocol.Frame.code
      checkFrame(f, after)
    }
  }

  it should "fail its check on a reply with a record dropped, duplicated or its i and j swapped" in {
    // The check must be able to fail: a real reply, then three broken copies of it.
    val rng = new Random(10)
    val (shift, dims) = (4, Seq(2, 2, 2))
    val f = BinFrame(BinScenes.straddling(rng, 24, shift, dims), shift, dims)
    onShell(8) { d =>
      val Seq(r) = d.exchange(Seq(frameWords(f)))
      checkFrame(f, r)
      r.records should be > 2L
      def withBody(body: Vector[Long], records: Long) = {
        val t = r.trailer.updated(Protocol.trailerWord("RECORDS"), records)
        val padded = body ++ Vector.fill((p.wordsPerBeat - body.length % p.wordsPerBeat) % p.wordsPerBeat)(0L)
        ShellReply(padded ++ t)
      }
      val recs = r.body.take(r.records.toInt)
      val mutants = Seq(
        "a record dropped" -> withBody(recs.tail, r.records - 1),
        "a record duplicated" -> withBody(recs :+ recs.head, r.records + 1),
        "i and j swapped" -> withBody(recs.updated(0, (recs(0) >> 16) | (recs(0) & 0xffff) << 16), r.records)
      )
      for ((name, m) <- mutants) withClue(s"$name: ") { an[org.scalatest.exceptions.TestFailedException] should be thrownBy checkFrame(f, m) }
    }
  }

  it should "add few cycles to a frame over the core alone (trailer DEVICE_CYCLES against the cycle model)" in {
    val rng = new Random(12)
    val (shift, dims) = (binning.maxShift, Seq(8, 8, 8))
    val f = BinFrame(BinScenes.uniform(rng, 64, shift, dims), shift, dims)
    onShell(9) { d =>
      d.exchange(Seq(frameWords(BinFrame(Nil, shift, dims)))) // after it the core has cleared its tables since reset
      val Seq(r) = d.exchange(Seq(frameWords(f)))
      checkFrame(f, r)
      // The core alone, offered a beat every cycle, and offered one as often as 128 bits a cycle carry 4 boxes (every 3rd).
      val alone = BinningCycleModel.run(binning, f)
      val paced = BinningCycleModel.run(binning, f, offer = t => t % 3 == 0)
      info(s"64 boxes: DEVICE_CYCLES ${r.deviceCycles} (intake ${r.intakeCycles}); cycle model: ${alone.cycles} " +
        s"(intake ${alone.intakeDone + 1}) with a beat every cycle, ${paced.cycles} (intake ${paced.intakeDone + 1}) with one every 3rd; " +
        s"first input beat to the trailer's TLAST: ${d.exchangeCycles} cycles")
      r.deviceCycles should be >= alone.cycles
      r.issueCycles shouldBe alone.issueCycles
    }
  }
}
