package bpaccel

import chisel3._
import chisel3.util._

/** One cycle of the schedule as the sequencer issues it. */
class ScheduleStep(p: AccelParams) extends Bundle {
  val bRows      = Vec(p.m, UInt(p.rowWidth.W)) // B port k's row
  val rotate     = UInt(p.laneWidth.W)          // lane k takes B data of memory (k + rotate) mod m
  val iBase      = UInt(p.indexWidth.W)         // lane k's A object is iBase + k
  val jBase      = UInt(p.indexWidth.W)         // lane k's B object is jBase + k
  val laneMask   = UInt(p.m.W)                  // lanes whose B object is < n
  val blockStart = Bool()                       // first cycle of a block: the captured next A block takes over
  val capture    = UInt(p.m.W)                  // one-hot: B port k reads the next block's A object k
}

/** The A/B address sequencer.
  *
  * Block b compares A objects b*m .. b*m+m-1 (held in registers, see
  * [[SeedEngine]]) with the B window. The B ports hold a window of m
  * consecutive objects starting at s = b*m+1: B port 0 at row b+1, the others
  * at row b. Each cycle the window slides by one object: the port holding
  * object s (port s mod m) advances one row, round robin. Lane k then
  * compares A object b*m+k with B object s+k, which lives in memory
  * (s+k) mod m, so the rotation is s mod m. A block ends after the cycle in
  * which s = n-1 (lane 0's partner is the last object); the next block exists
  * while b*m <= n-2 for it.
  *
  * In cycle k < m of a block, B port k reads row b+1: the next block's A
  * object k (`capture`). A block with a successor has n-1-b*m >= m+1 cycles,
  * so every such cycle is issued before the block ends.
  *
  * The block-end test is computed one cycle ahead (`blockEnd`,
  * `hasNextBlock` are registers), so no comparator sits between the state and
  * the next-state multiplexers of the rows and the rotation.
  */
class AddressSequencer(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val start   = Flipped(Valid(UInt(p.countWidth.W))) // n; a run with n < 2 does nothing
    val advance = Input(Bool())                        // downstream has room for one more cycle
    val active  = Output(Bool())
    val issue   = Valid(new ScheduleStep(p))
  })

  private val m = p.m
  val active       = RegInit(false.B)
  val base         = Reg(UInt(p.countWidth.W))  // b*m
  val blockRow     = Reg(UInt(p.rowWidth.W))    // b
  val s            = Reg(UInt(p.countWidth.W))  // window start
  val left         = Reg(UInt(p.countWidth.W))  // n-1-s: cycles after this one in the block
  val blockLeft    = Reg(UInt(p.countWidth.W))  // n-2-b*m
  val blockEnd     = Reg(Bool())                // left == 0
  val hasNextBlock = Reg(Bool())                // blockLeft >= m
  val blockStart   = Reg(Bool())
  val rotate       = Reg(UInt(p.laneWidth.W))   // s mod m
  val advancing    = Reg(UInt(m.W))             // one-hot of rotate: the B port that advances after this cycle
  val capture      = Reg(UInt(m.W))
  val bRows        = Reg(Vec(m, UInt(p.bRowWidth.W)))

  /** Block at `blockBase` whose remaining length after its first cycle is `cyclesAfter` = n-2-blockBase. */
  private def startBlock(blockBase: UInt, row: UInt, cyclesAfter: UInt): Unit = {
    base         := blockBase
    blockRow     := row
    s            := blockBase + 1.U
    left         := cyclesAfter
    blockLeft    := cyclesAfter
    blockEnd     := cyclesAfter === 0.U
    hasNextBlock := cyclesAfter >= m.U
    blockStart   := true.B
    rotate       := (1 % m).U
    advancing    := (1 << (1 % m)).U(m.W)
    capture      := 1.U
    for (k <- 0 until m) bRows(k) := (if (k == 0) row +& 1.U else row)
  }

  io.active := active
  io.issue.valid           := active && io.advance
  // A B row past the last only ever feeds lanes outside the mask, so its top bit can go.
  io.issue.bits.bRows      := VecInit(bRows.map(_(p.rowWidth - 1, 0)))
  io.issue.bits.rotate     := rotate
  io.issue.bits.iBase      := base
  io.issue.bits.jBase      := s
  // Lane k's B object s+k exists while n-s = left+1 > k.
  io.issue.bits.laneMask   := VecInit(Seq.tabulate(m)(k => left >= k.U)).asUInt
  io.issue.bits.blockStart := blockStart
  io.issue.bits.capture    := capture

  when(io.issue.valid) {
    blockStart := false.B
    capture    := (capture << 1)(m - 1, 0)
    when(!blockEnd) {
      s        := s + 1.U
      left     := left - 1.U
      blockEnd := left === 1.U
      for (k <- 0 until m) when(advancing(k)) { bRows(k) := bRows(k) + 1.U }
      if (m > 1) {
        rotate    := Mux(rotate === (m - 1).U, 0.U, rotate + 1.U)
        advancing := advancing(m - 2, 0) ## advancing(m - 1)
      }
    }.elsewhen(hasNextBlock) {
      startBlock(base + m.U, blockRow + 1.U, blockLeft - m.U)
    }.otherwise {
      active := false.B
    }
  }

  // While idle, block 0's state follows n, so the start only sets `active`:
  // the start's error decoding (n against the boxes loaded) then selects one
  // flip-flop instead of every register of the sequencer (it was the m = 8
  // critical path once the block-end test was registered).
  when(!active) { startBlock(0.U, 0.U, io.start.bits - 2.U) }
  when(io.start.valid) { active := io.start.bits >= 2.U }
}
