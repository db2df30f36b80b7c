package bpaccel.shell

import chisel3._
import chisel3.util._

import bpaccel.binning.{BinningCore, BinningError, BoxBeat, FrameHeader}

/** The FRAME command (docs/protocol.md) on a [[BinningCore]].
  *
  * Body: the header {n, shift, dims} as one item to the core's `frame` port,
  * then the boxes, up to `intakeBoxes` of them an item (the core's beat), to
  * `boxes`, each through a small queue. The beat with the n-th box carries
  * `last`; a frame of no boxes, or whose n is above the capacity, sends one
  * empty beat with `last` after its header (the core then reports
  * COUNT_OVER_CAPACITY itself, after the control has drained the packet).
  *
  * The core checks the content and reports the first offending box in its
  * summary, in stream order; the adapter maps its codes to the protocol's.
  * Two checks are the stream's, and the adapter turns each into one the core
  * makes at the same place, so that the first error stays first: a box with
  * a key wider than the device's reaches the core inverted (min x all ones,
  * max x 0), and its BOX_INVERTED at that box is reported as KEY_TOO_WIDE; a
  * header with a reserved bit set reaches it with shift 255 (BAD_GRID).
  *
  * A packet that ends before the n-th box (`cancel` with `ended`) ends the
  * core's frame with a last beat of the boxes that came whole: the core then
  * reports LENGTH_MISMATCH naming them, unless a box before them erred. Any
  * other cancel (an abort, an error in the header) aborts the core; the
  * summary then counts the records and boxes so far and no cycles.
  *
  * Each of the core's pairs is a record ({j, i} or i, j), all pairs of a core
  * beat in one cycle.
  */
class FrameAdapter(p: ShellParams) extends CoreAdapter(p, p.binning.get.pairsPerBeat * p.indexWords) {
  val opcode = Protocol.Frame
  private val b = p.binning.get
  private val w = b.intakeBoxes

  object Phase extends ChiselEnum { val Idle, Header, Boxes, Finishing = Value }
  val phase = RegInit(Phase.Idle)

  private val endsShort = io.cancel && io.ended && phase === Phase.Boxes
  val cancelling = RegNext(io.cancel && !endsShort, false.B)
  // The core aborts (and restarts) and its queues empty on a cancel: nothing of the command is left.
  val core = Module(new BinningCore(b))
  core.io.abort := cancelling
  private val datapathReset = reset.asBool || cancelling
  val headers = withReset(datapathReset) { Module(new Queue(new FrameHeader, 1)) }
  val beats   = withReset(datapathReset) { Module(new Queue(new BoxBeat(b), 2)) }
  core.io.frame <> headers.io.deq
  core.io.boxes <> beats.io.deq

  val boxesLeft    = Reg(UInt(32.W))
  val boxesIn      = Reg(UInt(32.W))
  val records      = Reg(UInt(32.W))
  val firstTooWide = Reg(Valid(UInt(32.W)))

  // ---- the item at the front of the window ----
  private val words = io.window.words
  // Header: n, shift, dims.
  private val n         = words(0)
  private val reserved  = words(1)(31, 8).orR || words(2)(31, 24).orR
  private val noBoxes   = n === 0.U || n > b.boxCapacity.U // the core reads no box of such a frame
  // Boxes: this item's count and their decoded keys.
  private val itemBoxes = Mux(boxesLeft >= w.U, w.U, boxesLeft)
  private val decoded   = Seq.tabulate(w)(l => StreamBox.decode(p, words.slice(l * p.boxWords, (l + 1) * p.boxWords)))

  io.need := Mux(phase === Phase.Header, p.frameHeaderWords.U,
    MuxLookup(itemBoxes, 0.U)((1 to w).map(k => k.U -> (k * p.boxWords).U)))
  io.last := MuxLookup(phase, false.B)(Seq(Phase.Header -> noBoxes, Phase.Boxes -> (boxesLeft <= w.U)))
  io.ready := MuxLookup(phase, false.B)(Seq(
    Phase.Header -> (headers.io.enq.ready && beats.io.enq.ready),
    Phase.Boxes  -> beats.io.enq.ready
  ))
  io.itemError.valid := false.B // every content check is the core's (see above)
  io.itemError.bits  := DontCare

  // LENGTH_MISMATCH's detail: the boxes the packet carried whole before its TLAST (n when data follows the last).
  private val lastSeen  = VecInit(io.window.last.zipWithIndex.map { case (l, i) => l && i.U < io.window.count })
  private val lastAt    = PriorityEncoder(lastSeen)
  private val wholeUpTo = MuxLookup(lastAt, 0.U)((0 until p.itemWords).map(e => e.U -> ((e + 1) / p.boxWords).U))
  io.position := boxesIn + Mux(phase === Phase.Boxes && lastSeen.asUInt.orR, wholeUpTo, 0.U)

  headers.io.enq.valid      := io.take && phase === Phase.Header
  headers.io.enq.bits.n     := n
  headers.io.enq.bits.shift := Mux(reserved, 255.U, words(1)(7, 0))
  headers.io.enq.bits.dims  := VecInit((0 until 3).map(a => words(2)(8 * a + 7, 8 * a)))

  // The beat of this item; after a short end, the boxes that came whole, kept until the queue has room.
  private val beat = Wire(new BoxBeat(b))
  private val boxesNow = Mux(io.ended, wholeUpTo, itemBoxes)
  beat.last := phase === Phase.Header || boxesLeft <= w.U || io.ended
  for ((lane, l) <- beat.boxes.zipWithIndex) {
    lane.valid := phase === Phase.Boxes && l.U < boxesNow
    lane.bits  := decoded(l).aabb
    when(decoded(l).tooWide) { // inverted on x: the core's BOX_INVERTED at this box
      lane.bits.min(0) := Fill(b.keyWidth, 1.U(1.W))
      lane.bits.max(0) := 0.U
    }
  }
  val lastBeat = RegInit(0.U.asTypeOf(Valid(new BoxBeat(b))))
  when(endsShort) { lastBeat.valid := true.B; lastBeat.bits := beat }
  when(lastBeat.valid && beats.io.enq.ready) { lastBeat.valid := false.B }
  when(cancelling) { lastBeat.valid := false.B }
  beats.io.enq.valid := io.take && (phase === Phase.Boxes || noBoxes) || lastBeat.valid
  beats.io.enq.bits  := Mux(lastBeat.valid, lastBeat.bits, beat)
  assert(!(lastBeat.valid && io.take), "an item was taken after the packet ended")
  assert(!headers.io.enq.valid || headers.io.enq.ready, "a frame header was taken without room")
  assert(!beats.io.enq.valid || beats.io.enq.ready, "boxes were taken without room")

  when(io.start) {
    phase := Phase.Header
    Seq(boxesIn, records).foreach(_ := 0.U)
    firstTooWide.valid := false.B
  }
  private val tooWideNow = decoded.zipWithIndex.map { case (d, l) => d.tooWide && l.U < boxesNow }
  when((io.take && phase === Phase.Boxes || endsShort) && !firstTooWide.valid && tooWideNow.reduce(_ || _)) {
    firstTooWide.valid := true.B
    firstTooWide.bits  := boxesIn + PriorityEncoder(tooWideNow)
  }
  when(endsShort) { boxesIn := boxesIn + wholeUpTo }
  when(io.take) {
    switch(phase) {
      is(Phase.Header) {
        boxesLeft := n
        phase     := Mux(noBoxes, Phase.Finishing, Phase.Boxes)
      }
      is(Phase.Boxes) {
        boxesLeft := boxesLeft - itemBoxes
        boxesIn   := boxesIn + itemBoxes
        when(boxesLeft <= w.U) { phase := Phase.Finishing }
      }
    }
  }

  // ---- records: each pair of a core beat is one ----
  private val pairs = core.io.pairs.bits.pairs
  assert(!core.io.pairs.valid || (1 until pairs.length).map(l => !pairs(l).valid || pairs(l - 1).valid).foldLeft(true.B)(_ && _),
    "a beat of pairs is not filled from its lowest lane")
  private val pairWords = pairs.flatMap { q =>
    if (p.indexWords == 1) Seq(Cat(q.bits.j.pad(16), q.bits.i.pad(16))) else Seq(q.bits.i.pad(32), q.bits.j.pad(32))
  }
  private val pairCount = PopCount(pairs.map(_.valid))
  io.records.valid      := core.io.pairs.valid && !cancelling // none after a cancel: the summary counts them all
  io.records.bits.words := VecInit(pairWords)
  io.records.bits.count := pairCount * p.indexWords.U
  core.io.pairs.ready   := io.records.ready
  when(io.records.fire) { records := records + pairCount }

  // ---- the summary: at once after a cancel, else the core's ----
  private val s = core.io.summary.bits
  io.summary.valid      := phase =/= Phase.Idle && (cancelling || core.io.summary.valid)
  core.io.summary.ready := io.summary.ready && !cancelling
  private val keyTooWide = s.error === BinningError.BoxInverted && firstTooWide.valid && s.detail === firstTooWide.bits
  private val code = Mux(keyTooWide, Protocol.KeyTooWide.code.U,
    MuxLookup(s.error.asUInt, 0.U)(Protocol.frameErrors.map { case (c, e) => c.U -> e.code.U }))
  private val ran = !cancelling
  private def counter(v: UInt): UInt = Mux(ran, v.pad(64), 0.U)
  io.summary.bits.records      := records
  io.summary.bits.boxes        := boxesIn
  io.summary.bits.cells        := 0.U
  io.summary.bits.runCycles    := counter(s.cycles - s.intakeCycles)
  io.summary.bits.intakeCycles := counter(s.intakeCycles)
  io.summary.bits.issueCycles  := counter(s.issueCycles)
  io.summary.bits.stallCycles  := counter(s.stallCycles)
  io.summary.bits.pairs        := counter(s.records)
  io.summary.bits.error.code   := Mux(ran, code, 0.U)
  io.summary.bits.error.detail := Mux(ran, s.detail, 0.U)
  when(io.summary.fire) { phase := Phase.Idle }
  when(io.cancel) { phase := Phase.Finishing }
}
