package bpaccel

import chisel3._
import chisel3.util._

/** The six coordinate buffers (min x, y, z, max x, y, z).
  *
  * Each buffer is built from m memories: object k lives in memory k mod m at
  * row k / m, so the m read ports see m consecutive objects in one cycle.
  * Each memory has one write port (loading) and one read port (the B window;
  * the A blocks are captured from it, see [[SeedEngine]]): the shape of a
  * simple dual-port block RAM, one DP16KD on ECP5 ([[CoordinateMemory]];
  * a read takes the memory style's latency).
  *
  * The write port is registered ([[CoordBuffer.writeLatency]]): a box
  * reaches its memory row a cycle after it is offered, and each lane's
  * write enable is a register of its own, so the load handshake does not
  * drive the 6m write ports across the die.
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
    /** Memory k's read data, the memory style's readLatency cycles after the read. */
    val data = Output(Vec(p.m, new Aabb(p.keyWidth)))
  })

  private def coords(box: Aabb): Seq[UInt] = box.min ++ box.max

  private val writeRow = RegNext(io.write.bits.row)
  private val writeBox = RegNext(io.write.bits.box)
  for (lane <- 0 until p.m) {
    val writeHere = RegNext(io.write.valid && io.write.bits.lane === lane.U, false.B)
    for ((wdata, c) <- coords(writeBox).zipWithIndex) {
      val mem = new CoordinateMemory(p.memoryStyle, p.depth, p.keyWidth)
      mem.write(writeHere, writeRow, wdata)
      coords(io.data(lane))(c) := mem.read(io.readEnable, io.rows(lane))
    }
  }
}

object CoordBuffer {
  /** Extra cycles of the registered write port: a box offered in cycle t can be read from cycle t + 1 + writeLatency on. */
  val writeLatency = 1
}
