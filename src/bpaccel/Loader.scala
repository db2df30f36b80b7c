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
  /** One-hot: bit k set when this is object k < m, one of block 0's A objects (the seed's A registers). */
  val firstBlockLane = UInt(p.m.W)
  /** This is object k < p.headObjects: for the stream, one its head registers keep. */
  val head = Bool()
}

/** A batch cell's box count, with what the front end tests of it decided as
  * the count is queued, so that no OR tree sits behind the queue's LUT RAM.
  */
class CellCount(p: AccelParams) extends Bundle {
  val count    = UInt(p.countWidth.W)
  val split    = UInt(p.countWidth.W) // RunRequest's
  val nonEmpty = Bool() // count =/= 0
}

object CellCount {
  def apply(p: AccelParams, request: RunRequest): CellCount = {
    val c = Wire(new CellCount(p))
    c.count    := request.count
    c.split    := request.split
    c.nonEmpty := request.count =/= 0.U
    c
  }
}

/** Numbers the boxes of a run in load order and refuses (with `overflow`)
  * any box beyond the capacity. A clear makes the next box object 0.
  */
class Loader(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val load     = Flipped(Valid(new Aabb(p.keyWidth))) // an accepted box
    // A box is offered that the load port takes unless a start or a batch's
    // first count is accepted in this cycle (which then clears the loader).
    val offered  = Input(Bool())
    val clear    = Input(Bool())
    val write    = Valid(new LoadWrite(p))
    // io.write.valid, unless a clear refused the box: free of the host's start
    // and count, for look-aheads whose error in a clearing cycle is harmless.
    val writeOffered = Output(Bool())
    val loaded   = Output(UInt(p.countWidth.W))
    // Of the stream's head registers, how many the boxes loaded leave empty:
    // headObjects - min(loaded, headObjects), a register.
    val headPad  = Output(UInt(log2Ceil(p.headObjects + 1).W))
    val overflow = Output(Bool()) // a box arrived when `capacity` were loaded; held until clear
  })
  private val m = p.m
  val loaded   = RegInit(0.U(p.countWidth.W)) // boxes since the clear
  val lane     = RegInit(0.U(p.laneWidth.W))
  val row      = RegInit(0.U(p.rowWidth.W))
  val overflow = RegInit(false.B)
  // Registers, not compares of `loaded` and `row`/`lane`: a write's valid and
  // block 0's lane reach the engine's per-lane registers through no compare
  // (seed m = 8's critical path ran from `loaded` through both to `loadRead`).
  val full     = RegInit(false.B) // loaded == capacity
  val firstBlockLane = RegInit(1.U(m.W)) // one-hot lane while the next box is object k < m, then 0
  val head     = RegInit(true.B)         // the next box is object k < headObjects
  val headPad  = RegInit(p.headObjects.U(log2Ceil(p.headObjects + 1).W)) // headObjects - min(loaded, headObjects)
  assert(full === (loaded === p.capacity.U), "the loader's full flag does not match its count")
  // Boxes are numbered in load order: the next box is object `loaded` (below the capacity while not full).
  private val index = loaded(p.indexWidth - 1, 0)
  private val firstBlockLaneOfIndex = VecInit(Seq.tabulate(m)(k => loaded === k.U)).asUInt
  assert(full || firstBlockLane === firstBlockLaneOfIndex, "the loader's block-0 lane does not match its index")
  assert(headPad === Mux(loaded < p.headObjects.U, p.headObjects.U - loaded, 0.U) && head === (headPad =/= 0.U),
    "the loader's head flag or pad does not match its count")

  io.write.valid      := io.load.valid && !full
  io.writeOffered     := io.offered && !full
  assert(!io.load.valid || io.offered, "a box was accepted that was not offered")
  assert(io.writeOffered === io.write.valid || io.clear, "a box offered to the loader was refused without a clear")
  io.write.bits.index := index
  io.write.bits.lane  := lane
  io.write.bits.row   := row
  io.write.bits.box   := io.load.bits
  io.write.bits.firstBlockLane := firstBlockLane
  io.write.bits.head  := head
  io.loaded           := loaded
  io.headPad          := headPad
  io.overflow         := overflow

  when(io.load.valid) {
    when(full) {
      overflow := true.B
    }.otherwise {
      loaded := loaded + 1.U
      full   := loaded === (p.capacity - 1).U
      firstBlockLane := (firstBlockLane << 1)(m - 1, 0)
      when(head) {
        headPad := headPad - 1.U
        head    := headPad =/= 1.U
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
    loaded   := 0.U
    lane     := 0.U
    row      := 0.U
    overflow := false.B
    full     := false.B
    firstBlockLane := 1.U
    head     := true.B
    headPad  := p.headObjects.U
  }
}
