package bpaccel

import chisel3._
import chisel3.util._

/** Where a loaded box goes: its object index (load order) and, for the
  * striped buffers of the seed architecture, memory `lane` = index mod m at
  * row `row` = index / m.
  */
class LoadWrite(p: AccelParams) extends Bundle {
  val index = UInt(p.indexWidth.W)
  val lane  = UInt(p.laneWidth.W)
  val row   = UInt(p.rowWidth.W)
  val box   = new Aabb(p.keyWidth)
  /** One-hot: bit k set when this is object k < m, one of block 0's A objects. */
  val firstBlockLane = UInt(p.m.W)
  /** This is object 0 .. m, which the stream's B window takes from the load port. */
  val head = Bool()
}

/** A batch cell's box count, with the loader's numbering for it decided as
  * the count is queued: deciding it from the queue's output put the queue's
  * LUT RAM and two count compares in front of the loader's index (stream
  * m = 32's critical path, 91.3 MHz). Only where loads overlap runs do the
  * last two fields have bits.
  */
class CellCount(p: AccelParams) extends Bundle {
  val count     = UInt(p.countWidth.W)
  val nonEmpty  = Bool() // count =/= 0: the OR tree behind the queue's LUT RAM was the next path (84.7 MHz)
  val headLast  = UInt((if (p.overlapsLoads) 1 else 0).W) // p.loadsHeadLast(count)
  val lastIndex = UInt((if (p.overlapsLoads) p.indexWidth else 0).W) // count - 1, when head last
}

object CellCount {
  def apply(p: AccelParams, count: UInt): CellCount = {
    val c = Wire(new CellCount(p))
    c.count    := count
    c.nonEmpty := count =/= 0.U
    if (p.overlapsLoads) {
      c.headLast  := (count >= (p.m + 2).U && count <= p.capacity.U).asUInt
      c.lastIndex := (count - 1.U)(p.indexWidth - 1, 0)
    } else {
      c.headLast  := 0.U
      c.lastIndex := 0.U
    }
    c
  }
}

/** Numbers the boxes of a run and refuses (with `overflow`) any box beyond
  * the capacity. A clear makes the next box object 0, or, when `headLast`
  * gives the count of a batch's cell that is sent head last
  * ([[AccelParams.loadsHeadLast]]), object m+1: boxes m+1 .. n-1 come
  * first, then 0 .. m.
  */
class Loader(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val load     = Flipped(Valid(new Aabb(p.keyWidth))) // an accepted box
    val clear    = Input(Bool())
    // With clear: the next cell's count, when it may be sent head last (only where loads overlap runs).
    val headLast = Option.when(p.overlapsLoads)(Flipped(Valid(new CellCount(p))))
    val write    = Valid(new LoadWrite(p))
    val loaded   = Output(UInt(p.countWidth.W))
    val overflow = Output(Bool()) // a box arrived when `capacity` were loaded; held until clear
    val nextHead = Output(Bool()) // the next box is object 0 .. m
  })
  private val m = p.m
  val loaded   = RegInit(0.U(p.countWidth.W)) // boxes since the clear
  val index    = RegInit(0.U(p.indexWidth.W)) // object index of the next box
  val lane     = RegInit(0.U(p.laneWidth.W))
  val row      = RegInit(0.U(p.rowWidth.W))
  val overflow = RegInit(false.B)
  // Head last: after object lastIndex = n-1 the numbering wraps to 0.
  val wraps     = RegInit(false.B)
  val inOrder   = RegInit(true.B) // this cell is not sent head last
  val lastIndex = Reg(UInt(p.indexWidth.W))
  // Registers, not compares of `loaded` and `row`/`lane`: a write's valid and
  // block 0's lane reach the engine's per-lane registers through no compare
  // (seed m = 8's critical path ran from `loaded` through both to `loadRead`).
  val full           = RegInit(false.B) // loaded == capacity
  val firstBlockLane = RegInit(1.U(m.W)) // one-hot lane while index < m, then 0
  val head           = RegInit(true.B)   // index <= m
  assert(full === (loaded === p.capacity.U), "the loader's full flag does not match its count")
  private val firstBlockLaneOfIndex = VecInit(Seq.tabulate(m)(k => index === k.U)).asUInt
  assert(full || firstBlockLane === firstBlockLaneOfIndex, "the loader's block-0 lane does not match its index")
  assert(full || head === (index <= m.U), "the loader's head flag does not match its index")
  assert(!inOrder || full || index === loaded, "the loader numbered boxes out of order without a head-last cell")
  // Only the seed stripes, and it never sends a cell head last.
  assert(inOrder || p.overlapsLoads.B, "a head-last cell on an architecture that loads in order")

  io.write.valid      := io.load.valid && !full
  io.write.bits.index := index
  io.write.bits.lane  := lane
  io.write.bits.row   := row
  io.write.bits.box   := io.load.bits
  io.write.bits.firstBlockLane := firstBlockLane
  io.write.bits.head  := head
  io.loaded           := loaded
  io.overflow         := overflow
  io.nextHead         := head

  when(io.load.valid) {
    when(full) {
      overflow := true.B
    }.otherwise {
      loaded := loaded + 1.U
      full   := loaded === (p.capacity - 1).U
      when(wraps && index === lastIndex) {
        index          := 0.U
        wraps          := false.B
        head           := true.B
        firstBlockLane := 1.U
      }.otherwise {
        index          := index + 1.U
        head           := head && index =/= m.U
        firstBlockLane := (firstBlockLane << 1)(m - 1, 0)
      }
      if (m == 1) row := row + 1.U
      else {
        val lastLane = lane === (m - 1).U
        lane := Mux(lastLane, 0.U, lane + 1.U)
        when(lastLane) { row := row + 1.U }
      }
    }
  }
  when(io.clear) {
    val headLastCell = io.headLast.map(h => h.valid && h.bits.headLast.asBool).getOrElse(false.B)
    loaded   := 0.U
    lane     := 0.U
    row      := 0.U
    overflow := false.B
    full     := false.B
    wraps    := headLastCell
    inOrder  := !headLastCell
    for (h <- io.headLast) lastIndex := h.bits.lastIndex
    index          := Mux(headLastCell, (m + 1).U, 0.U)
    head           := !headLastCell
    firstBlockLane := Mux(headLastCell, 0.U, 1.U)
  }
}
