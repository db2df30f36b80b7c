package bpaccel

import chisel3._
import chisel3.util._

/** The six coordinate buffers (min x, y, z, max x, y, z).
  *
  * Each buffer is a 2m-port memory built from m dual-port memories: object k
  * lives in memory k mod m at row k / m, so the A ports read a whole block of
  * m consecutive objects in one cycle while the B ports read one row each.
  * Port A also writes during loading, so each memory has exactly one
  * read/write port and one read port: the shape of an FPGA true dual-port
  * block RAM. Reads take one cycle (synchronous, as block RAM).
  */
class CoordBuffer(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val write = Flipped(Valid(new Bundle {
      val lane = UInt(p.laneWidth.W)
      val row  = UInt(p.rowWidth.W)
      val box  = new Aabb(p.keyWidth)
    }))
    val readEnable = Input(Bool())
    val aRow       = Input(UInt(p.rowWidth.W))
    val bRows      = Input(Vec(p.m, UInt(p.rowWidth.W)))
    /** Memory k's port A data, one cycle after the read. */
    val a = Output(Vec(p.m, new Aabb(p.keyWidth)))
    /** Memory k's port B data, one cycle after the read. */
    val b = Output(Vec(p.m, new Aabb(p.keyWidth)))
  })

  private def coords(box: Aabb): Seq[UInt] = box.min ++ box.max

  for (lane <- 0 until p.m) {
    val writeHere = io.write.valid && io.write.bits.lane === lane.U
    val portARow  = Mux(writeHere, io.write.bits.row, io.aRow)
    for ((wdata, c) <- coords(io.write.bits.box).zipWithIndex) {
      val mem = SyncReadMem(p.depth, UInt(p.keyWidth.W))
      coords(io.a(lane))(c) := mem.readWrite(portARow, wdata, writeHere || io.readEnable, writeHere)
      coords(io.b(lane))(c) := mem.read(io.bRows(lane), io.readEnable)
    }
  }
}
