package bpaccel

import chisel3._
import chisel3.experimental.noPrefix
import chisel3.util._

/** The six coordinate buffers (min x, y, z, max x, y, z).
  *
  * Each buffer is built from m memories: object k lives in memory k mod m at
  * row k / m, so the m read ports see m consecutive objects in one cycle.
  * Each memory has one write port (loading) and one read port (the B window;
  * the A blocks are captured from it, see [[SeedEngine]]): the shape of a
  * simple dual-port block RAM, one DP16KD on ECP5. Reads take one cycle
  * (synchronous, as block RAM), or two with [[MemoryStyle.Ecp5OutputRegister]],
  * whose memories include the first output register ([[readLatency]]).
  *
  * The write port is registered ([[CoordBuffer.writeLatency]]): a box
  * reaches its memory row a cycle after it is offered, and each lane's
  * write enable is a register of its own. The enables drove the memories'
  * write ports straight from the load handshake (seed m = 8's critical path,
  * 96.8 MHz: load ready -> a memory's write enable, 8.4 ns of wire).
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
    /** Memory k's read data, readLatency cycles after the read. */
    val data = Output(Vec(p.m, new Aabb(p.keyWidth)))
  })

  private def coords(box: Aabb): Seq[UInt] = box.min ++ box.max

  private val writeRow = RegNext(io.write.bits.row)
  private val writeBox = RegNext(io.write.bits.box)
  for (lane <- 0 until p.m) {
    val writeHere = RegNext(io.write.valid && io.write.bits.lane === lane.U, false.B)
    for ((wdata, c) <- coords(writeBox).zipWithIndex) {
      // noPrefix: the memory keeps its plain name (module mem_<rows>x<width>), as before the styles.
      coords(io.data(lane))(c) := noPrefix(p.memoryStyle match {
        case MemoryStyle.Inferred =>
          val mem = SyncReadMem(p.depth, UInt(p.keyWidth.W))
          when(writeHere) { mem.write(writeRow, wdata) }
          mem.read(io.rows(lane), io.readEnable)
        case MemoryStyle.Ecp5OutputRegister =>
          val mem = Module(new RegisteredReadMemory(p.depth, p.keyWidth))
          mem.io.writeEnable := writeHere
          mem.io.writeRow    := writeRow
          mem.io.writeData   := wdata
          mem.io.readEnable  := io.readEnable
          mem.io.readRow     := io.rows(lane)
          mem.io.readData
      })
    }
  }
}

object CoordBuffer {
  /** Extra cycles of the registered write port: a box offered in cycle t can be read from cycle t + 1 + writeLatency on. */
  val writeLatency = 1

  /** Cycles from a read's rows to [[CoordBuffer]]'s data. */
  def readLatency(p: AccelParams): Int = p.memoryStyle match {
    case MemoryStyle.Inferred           => 1
    case MemoryStyle.Ecp5OutputRegister => RegisteredReadMemory.readLatency
  }
}
