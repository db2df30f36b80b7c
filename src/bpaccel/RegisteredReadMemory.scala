package bpaccel

import chisel3._
import chisel3.util._

/** A simple dual-port memory whose read data passes one register: two cycles
  * from a read's row to its data, which then holds until the next read's data
  * arrives (the register loads only one cycle after an enabled read).
  *
  * This is a `SyncReadMem` followed by one `Pipe` stage, in a module of its
  * own so that the FPGA flow can build it from DP16KD block RAMs with their
  * output register on (REGMODE OUTREG): the register then sits inside the
  * block RAM, whose clock-to-output is far shorter than the unregistered
  * read's. Yosys cannot map a fabric register into OUTREG by itself. The
  * flow replaces this module, by name, with scripts/fpga/ecp5/
  * Ecp5RegisteredReadMemory.v (checked against this one by
  * [[RegisteredReadMemorySpec]]); every simulation and proof runs this
  * Chisel description.
  *
  * A row read in the cycle it is written gives undefined data on the DP16KD
  * (its two ports collide; the write itself succeeds). The seed does such
  * reads while loading (every port reads row 0, only one lane's data is
  * used), so they are allowed, but their data is poison here (the word
  * inverted): a design that used it would fail its cycle-exact tests.
  */
class RegisteredReadMemory(val rows: Int, val width: Int) extends Module {
  require(rows >= 1 && width >= 1, s"RegisteredReadMemory needs rows >= 1 and width >= 1, got $rows x $width")
  private val rowBits = log2Ceil(rows).max(1)
  override def desiredName: String = MemoryStyle.Ecp5OutputRegister.moduleName(rows, width)

  val io = IO(new Bundle {
    val writeEnable = Input(Bool())
    val writeRow    = Input(UInt(rowBits.W))
    val writeData   = Input(UInt(width.W))
    val readEnable  = Input(Bool())
    val readRow     = Input(UInt(rowBits.W))
    /** The data of the latest read that is two cycles or more old. */
    val readData = Output(UInt(width.W))
  })
  // The FPGA flow swaps this module for its DP16KD version by name and port
  // list: a read enable tied high (the seed's) must not be optimised away.
  dontTouch(io)

  private val mem = SyncReadMem(rows, UInt(width.W))
  when(io.writeEnable) { mem.write(io.writeRow, io.writeData) }
  private val read      = mem.read(io.readRow, io.readEnable)
  private val collision = RegNext(io.writeEnable && io.readEnable && io.writeRow === io.readRow, false.B)
  io.readData := RegEnable(Mux(collision, ~read, read), RegNext(io.readEnable, false.B))
}

object RegisteredReadMemory {
  /** Module names start with this; the FPGA flow finds them by it. */
  val namePrefix = "RegisteredReadMemory_"

  /** Deepest memory one column of DP16KD holds (2048 x 9); deeper needs a cascade, not built. */
  val maxEcp5Rows = 2048

  /** Cycles from a read's row to its data. */
  val readLatency = 2
}
