package bpaccel

import chisel3._
import chisel3.util._

/** The six coordinate buffers (min x, y, z, max x, y, z).
  *
  * Each buffer is built from m memories: object k lives in memory k mod m at
  * row k / m, so the m read ports see m consecutive objects in one cycle.
  * Each memory has one write port (loading) and one read port (the B window;
  * the A blocks are captured from it, see [[SeedEngine]]): the shape of a
  * simple dual-port block RAM, one DP16KD on ECP5. Reads take one cycle
  * (synchronous, as block RAM).
  */
class CoordBuffer(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val write = Flipped(Valid(new Bundle {
      val lane = UInt(p.laneWidth.W)
      val row  = UInt(p.rowWidth.W)
      val box  = new Aabb(p.keyWidth)
    }))
    val readEnable = Input(Bool())
    val rows       = Input(Vec(p.m, UInt(p.rowWidth.W)))
    /** Memory k's read data, one cycle after the read. */
    val data = Output(Vec(p.m, new Aabb(p.keyWidth)))
  })

  private def coords(box: Aabb): Seq[UInt] = box.min ++ box.max

  for (lane <- 0 until p.m) {
    val writeHere = io.write.valid && io.write.bits.lane === lane.U
    for ((wdata, c) <- coords(io.write.bits.box).zipWithIndex) {
      val mem = SyncReadMem(p.depth, UInt(p.keyWidth.W))
      when(writeHere) { mem.write(io.write.bits.row, wdata) }
      coords(io.data(lane))(c) := mem.read(io.rows(lane), io.readEnable)
    }
  }
}
