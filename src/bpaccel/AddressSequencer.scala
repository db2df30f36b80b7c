package bpaccel

import chisel3._
import chisel3.util._

/** One cycle of the schedule as the sequencer issues it. */
class ScheduleStep(p: AccelParams) extends Bundle {
  val aRow     = UInt(p.rowWidth.W)             // every A port reads this row: block b
  val bRows    = Vec(p.m, UInt(p.rowWidth.W))   // B port k's row
  val rotate   = UInt(p.laneWidth.W)            // lane k takes B data of memory (k + rotate) mod m
  val iBase    = UInt(p.indexWidth.W)           // lane k's A object is iBase + k
  val jBase    = UInt(p.indexWidth.W)           // lane k's B object is jBase + k
  val laneMask = UInt(p.m.W)                    // lanes whose B object is < n
}

/** The A/B address sequencer.
  *
  * Block b: every A port reads row b (objects b*m .. b*m+m-1). The B ports
  * hold a window of m consecutive objects starting at s = b*m+1: B port 0 at
  * row b+1, the others at row b. Each cycle the window slides by one object:
  * the port holding object s (port s mod m) advances one row, round robin.
  * Lane k then compares A object b*m+k with B object s+k, which lives in
  * memory (s+k) mod m, so the rotation is s mod m. A block ends after the
  * cycle in which s = n-1 (lane 0's partner is the last object); the run ends
  * after the block in which b*m >= n-2 would no longer hold for the next one.
  */
class AddressSequencer(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val start   = Flipped(Valid(UInt(p.countWidth.W))) // n; a run with n < 2 does nothing
    val advance = Input(Bool())                        // downstream has room for one more cycle
    val active  = Output(Bool())
    val issue   = Valid(new ScheduleStep(p))
  })

  private val m = p.m
  val active = RegInit(false.B)
  val n      = Reg(UInt(p.countWidth.W))
  val iBase  = Reg(UInt(p.countWidth.W))  // b*m
  val aRow   = Reg(UInt(p.rowWidth.W))    // b
  val s      = Reg(UInt(p.countWidth.W))  // window start
  val rotate = Reg(UInt(p.laneWidth.W))   // s mod m, also the next B port to advance
  val bRows  = Reg(Vec(m, UInt(p.bRowWidth.W)))

  private def startBlock(base: UInt, row: UInt): Unit = {
    iBase  := base
    aRow   := row
    s      := base + 1.U
    rotate := (1 % m).U
    for (k <- 0 until m) bRows(k) := (if (k == 0) row +& 1.U else row)
  }

  io.active := active
  io.issue.valid         := active && io.advance
  io.issue.bits.aRow     := aRow
  // A B row past the last only ever feeds lanes outside the mask, so its top bit can go.
  io.issue.bits.bRows    := VecInit(bRows.map(_(p.rowWidth - 1, 0)))
  io.issue.bits.rotate   := rotate
  io.issue.bits.iBase    := iBase
  io.issue.bits.jBase    := s
  val remaining = n - s // >= 1 while active
  io.issue.bits.laneMask := VecInit(Seq.tabulate(m)(k => remaining > k.U)).asUInt

  when(io.issue.valid) {
    when(s === n - 1.U) {
      val nextBase = iBase +& m.U
      when(nextBase + 1.U >= n) {
        active := false.B
      }.otherwise {
        startBlock(nextBase, aRow + 1.U)
      }
    }.otherwise {
      s := s + 1.U
      if (m == 1) bRows(0) := bRows(0) + 1.U
      else {
        bRows(rotate) := bRows(rotate) + 1.U
        rotate        := Mux(rotate === (m - 1).U, 0.U, rotate + 1.U)
      }
    }
  }

  when(io.start.valid) {
    n      := io.start.bits
    active := io.start.bits >= 2.U
    startBlock(0.U, 0.U)
  }
}
