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
}

/** Numbers the boxes of a run in load order and refuses (with `overflow`)
  * any box beyond the capacity. A start (`clear`) makes the next box object 0.
  */
class Loader(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val load     = Flipped(Valid(new Aabb(p.keyWidth))) // an accepted box
    val clear    = Input(Bool())
    val write    = Valid(new LoadWrite(p))
    val loaded   = Output(UInt(p.countWidth.W))
    val overflow = Output(Bool()) // a box arrived when `capacity` were loaded; held until clear
  })
  private val m = p.m
  val loaded   = RegInit(0.U(p.countWidth.W))
  val lane     = RegInit(0.U(p.laneWidth.W))
  val row      = RegInit(0.U(p.rowWidth.W))
  val overflow = RegInit(false.B)
  val full     = loaded === p.capacity.U

  io.write.valid      := io.load.valid && !full
  io.write.bits.index := loaded
  io.write.bits.lane  := lane
  io.write.bits.row   := row
  io.write.bits.box   := io.load.bits
  io.loaded           := loaded
  io.overflow         := overflow

  when(io.load.valid) {
    when(full) {
      overflow := true.B
    }.otherwise {
      loaded := loaded + 1.U
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
  }
}
