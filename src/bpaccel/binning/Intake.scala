package bpaccel.binning

import chisel3._
import chisel3.util._

import bpaccel.Aabb

/** One box's side of a cell on one axis: the local cell coordinate, whether
  * the box starts there, and its key offsets clamped to the cell.
  */
class AxisPart(p: BinningParams, axis: Int) extends Bundle {
  val cell  = UInt(p.localCellBitsPerAxis(axis).W)
  val start = Bool()
  val min   = UInt(p.localBits.W)
  val max   = UInt(p.localBits.W)
}

/** A box decoded against the frame's grid: its index, its first error (if
  * any) and, per axis and group class v (cell mod 2^a), the part of the cell
  * of class v it covers (valid when it covers one).
  */
class BoxCells(p: BinningParams) extends Bundle {
  val valid = Bool()
  val index = UInt(32.W)
  val error = BinningError()
  val parts = MixedVec((0 until 3).map(a => Vec(1 << p.groupBits(a), Valid(new AxisPart(p, a)))))
}

object BoxCells {
  /** Decodes box `box` (index `index`) for the grid (n, shift, dims). */
  def apply(p: BinningParams, box: Valid[Aabb], index: UInt, n: UInt, shift: UInt, dims: Vec[UInt]): BoxCells = {
    val d = Wire(new BoxCells(p))
    d.valid := box.valid
    d.index := index
    val lo = box.bits.min.map(_ >> shift)
    val hi = box.bits.max.map(_ >> shift)
    // The offset bits of a key, (1 << shift) - 1 over localBits bits: bit i is set when i < shift.
    val lowMask  = VecInit((0 until p.localBits).map(i => shift > i.U)).asUInt
    val inverted = (0 until 3).map(a => box.bits.min(a) > box.bits.max(a)).reduce(_ || _)
    val outside  = (0 until 3).map(a => if (p.has(BinningFault.OutOfGridOffByOne)) hi(a) > dims(a) else hi(a) >= dims(a)).reduce(_ || _)
    val wide     = (0 until 3).map(a => hi(a) > lo(a) +& 1.U).reduce(_ || _)
    d.error := MuxCase(BinningError.None, Seq(
      (index >= n) -> BinningError.LengthMismatch,
      inverted     -> BinningError.BoxInverted,
      outside      -> BinningError.KeyOutOfGrid,
      wide         -> BinningError.BoxSpansCells
    ))
    for (a <- 0 until 3; v <- 0 until (1 << p.groupBits(a))) {
      val ga      = p.groupBits(a)
      val single  = lo(a) === hi(a)
      val usesLo  = lo(a)(ga - 1, 0) === v.U
      val usesHi  = hi(a)(ga - 1, 0) === v.U && !single
      val part    = d.parts(a)(v)
      val minOff  = box.bits.min(a)(p.localBits - 1, 0) & lowMask
      val maxOff  = box.bits.max(a)(p.localBits - 1, 0) & lowMask
      part.valid      := usesLo || usesHi
      part.bits.start := usesLo
      val bits    = p.localCellBitsPerAxis(a)
      part.bits.cell  := (if (bits == 0) 0.U(0.W) else (Mux(usesLo, lo(a), hi(a)) >> ga)(bits - 1, 0))
      part.bits.min   := Mux(usesLo, minOff, 0.U)
      part.bits.max   := Mux(usesLo && !single, lowMask, maxOff)
    }
    d
  }

  /** Whether a decoded box covers a cell of group `group` (whatever its error). */
  def covers(p: BinningParams, d: BoxCells, group: Int): Bool = parts(p, d, group).map(_.valid).reduce(_ && _)

  private def parts(p: BinningParams, d: BoxCells, group: Int): Seq[Valid[AxisPart]] = {
    val classOf = (0 until 3).map(a => (group >> p.groupBits.take(a).sum) & ((1 << p.groupBits(a)) - 1))
    (0 until 3).map(a => d.parts(a)(classOf(a)))
  }

  /** The entry a decoded box makes in group `group` (valid when it covers a cell of that group). */
  def entry(p: BinningParams, d: BoxCells, group: Int): Valid[BinEntry] = {
    val e = Wire(Valid(new BinEntry(p)))
    val parts = this.parts(p, d, group)
    e.valid := d.valid && d.error === BinningError.None && covers(p, d, group)
    for (a <- 0 until 3) {
      e.bits.min(a)    := parts(a).bits.min
      e.bits.max(a)    := parts(a).bits.max
      e.bits.starts(a) := parts(a).bits.start
    }
    e.bits.index := d.index(p.indexWidth - 1, 0)
    val cell = Cat(parts.reverse.map(_.bits.cell).filter(_.getWidth > 0))
    e.bits.cell := (if (p.localCellBitsPerAxis.sum == 0) 0.U else cell)
    e
  }
}

/** What the intake offers one group in a cycle, and whether the group takes it. */
class GroupPush(p: BinningParams) extends Bundle {
  val offer = Output(Vec(p.intakeBoxes, Valid(new BinEntry(p)))) // the held beat's entries for this group, by lane
  val room  = Input(new QueueRoom(p)) // which of the group's queues can take one more in this cycle
  val push  = Output(Bool()) // it does
}

/** Which of a group's intake queues have room: its beat queue and each lane's entry queue. */
class QueueRoom(p: BinningParams) extends Bundle {
  val beat  = Bool()
  val lanes = Vec(p.intakeBoxes, Bool())
}

/** Takes the frame's boxes, numbers them in stream order, decodes each
  * against the grid and routes its entries to the groups.
  *
  * One register holds a decoded beat. It moves on when an error was raised
  * before (draining the packet), when its beat raises one (the first box with
  * an error, else LENGTH_MISMATCH when its `last` comes before n boxes; the
  * beat then queues nothing), or when every group it has entries for has room
  * for them; those entries are then queued. GROUP_OVERFLOW is decided here, by
  * counting each group's entries as they are queued, so errors come in
  * stream order. The boxes port is ready while the register is empty or moves
  * on, until the beat with `last` is taken.
  *
  * Whether the held beat moves is decided over all groups in one cycle, and
  * it enables every register of the next beat. So what the decision reads of
  * the held beat (which groups each box covers, how many entries it brings
  * each group, whether a box has an error) is computed as the beat is taken
  * and registered beside it: the decision starts from registers.
  */
class Intake(p: BinningParams) extends Module {
  private val w = p.intakeBoxes
  val io = IO(new Bundle {
    val frameStart  = Input(Bool()) // the header is accepted in this cycle: a new frame
    val headerError = Input(Bool()) // ... and it has an error: drain the packet
    val active      = Input(Bool()) // the frame's intake is under way
    val n           = Input(UInt(32.W))
    val shift       = Input(UInt(p.shiftWidth.W))
    val dims        = Input(Vec(3, UInt(p.dimWidth.W)))
    val boxes       = Flipped(Decoupled(new BoxBeat(p)))
    val groups      = Vec(p.groups, new GroupPush(p))
    val error       = Valid(new Bundle { val code = BinningError(); val detail = UInt(32.W) }) // raised in this cycle
    val lastTaken   = Output(Bool())
    val holding     = Output(Bool()) // the register holds a beat
    val received    = Output(UInt(32.W))
  })

  val received    = RegInit(0.U(32.W))
  val lastTaken   = RegInit(false.B)
  val errorRaised = RegInit(false.B)
  val held        = RegInit(false.B)
  val beat        = Reg(Vec(w, new BoxCells(p)))
  val beatCovers  = Reg(Vec(p.groups, Vec(w, Bool()))) // of the held beat: lane l's box covers a cell of group gr
  val beatCounts  = Reg(Vec(p.groups, UInt(log2Ceil(w + 1).W))) // ... the entries it brings to group gr
  val beatError   = Reg(Bool()) // ... a box of it has an error of its own
  val beatEnd     = Reg(UInt(32.W)) // boxes received once this beat is counted
  val count       = PopCount(io.boxes.bits.boxes.map(_.valid))
  // Entries each group may still take (GROUP_OVERFLOW past it), and the same capped at w: a beat
  // brings at most w entries to a group, so comparing with the capped room needs no wide compare.
  val room = RegInit(VecInit(Seq.fill(p.groups)(p.groupCapacity.U(p.entryCountWidth.W))))
  private def capped(r: UInt): UInt = Mux(r >= w.U, w.U, r(log2Ceil(w + 1) - 1, 0))
  val cappedRoom = RegInit(VecInit(Seq.fill(p.groups)(p.groupCapacity.min(w).U(log2Ceil(w + 1).W))))

  assert(!io.boxes.valid || (1 until w).map(l => !io.boxes.bits.boxes(l).valid || io.boxes.bits.boxes(l - 1).valid).foldLeft(true.B)(_ && _),
    "a beat of boxes is not filled from its lowest lane")

  // ---- the held beat: errors, entries, room ----
  val entries = Seq.tabulate(p.groups, w)((gr, l) => BoxCells.entry(p, beat(l), gr))
  val over = Seq.tabulate(p.groups, w) { (gr, l) =>
    val upTo = PopCount(entries(gr).take(l + 1).map(_.valid))
    entries(gr)(l).valid && upTo > cappedRoom(gr)
  }
  val laneError = Seq.tabulate(w) { l =>
    val code = Wire(BinningError())
    code := Mux(beat(l).error =/= BinningError.None, beat(l).error,
      Mux(VecInit(over.map(_(l))).asUInt.orR, BinningError.GroupOverflow, BinningError.None))
    (beat(l).valid && code =/= BinningError.None, code)
  }
  val anyLaneError = laneError.map(_._1).reduce(_ || _)
  // Whether the beat moves is decided every cycle across all groups, so it is
  // computed flat: a lane's own error, else a group's entries beyond its room
  // (counted without the error term, which only matters when a lane's own
  // error raises anyway), else the last beat short of n (decided when the
  // beat was taken: n is fixed during the intake).
  val covers    = beatCovers.map(_.toSeq)
  val overflows = (0 until p.groups).map(gr => beatCounts(gr) > cappedRoom(gr))
  val endsShort = RegEnable(io.boxes.bits.last && received + count < io.n, io.boxes.fire) // of the held beat
  val raising   = beatError || overflows.reduce(_ || _) || endsShort
  val raises    = held && !errorRaised && raising
  val queued    = (0 until p.groups).map { gr =>
    val r = io.groups(gr).room
    !covers(gr).reduce(_ || _) || (r.beat && covers(gr).zip(r.lanes).map { case (c, free) => !c || free }.reduce(_ && _))
  }
  val pushes = held && !errorRaised && !raising && queued.reduce(_ && _)
  val moves  = held && (errorRaised || raises || pushes)

  io.error.valid := raises
  io.error.bits.code := Mux(anyLaneError, PriorityMux(laneError.map(_._1), laneError.map(_._2)), BinningError.LengthMismatch)
  io.error.bits.detail := Mux(anyLaneError, PriorityMux(laneError.map(_._1), beat.map(_.index)), beatEnd)
  when(raises) { errorRaised := true.B }

  for (gr <- 0 until p.groups) {
    io.groups(gr).offer := VecInit(entries(gr))
    io.groups(gr).push  := pushes && covers(gr).reduce(_ || _)
    val left = room(gr) - beatCounts(gr)
    when(pushes) { room(gr) := left; cappedRoom(gr) := capped(left) }
  }

  // ---- taking the next beat ----
  io.boxes.ready := io.active && !lastTaken && (!held || moves)
  if (p.has(BinningFault.ReceivedCountsOffers)) when(io.boxes.valid && !io.boxes.ready) { received := received + count }
  when(io.boxes.fire) {
    val decoded = (0 until w).map(l => BoxCells(p, io.boxes.bits.boxes(l), received + l.U, io.n, io.shift, io.dims))
    for (l <- 0 until w) beat(l) := decoded(l)
    for (gr <- 0 until p.groups) {
      val c = decoded.map(d => d.valid && BoxCells.covers(p, d, gr))
      beatCovers(gr) := VecInit(c)
      beatCounts(gr) := PopCount(c)
    }
    beatError := decoded.map(d => d.valid && d.error =/= BinningError.None).reduce(_ || _)
    beatEnd  := received + count
    received := received + count
    when(io.boxes.bits.last) { lastTaken := true.B }
  }
  held := io.boxes.fire || (held && !moves)

  when(io.frameStart) {
    received    := 0.U
    lastTaken   := false.B
    errorRaised := io.headerError
    held        := false.B
    for (gr <- 0 until p.groups) { room(gr) := p.groupCapacity.U; cappedRoom(gr) := p.groupCapacity.min(w).U }
  }

  io.lastTaken := lastTaken
  io.holding   := held
  io.received  := received
}
