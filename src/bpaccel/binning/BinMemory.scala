package bpaccel.binning

import chisel3._
import chisel3.util._

import bpaccel.{MemoryStyle, RegisteredReadMemory}

/** One of a group's two large memories (entries, order): a simple dual-port
  * memory whose write port takes its request from registers (a request
  * lands in the memory a cycle later) and whose read data comes
  * `memoryReadLatency` cycles after the read, through free-running output
  * registers. Built as the coordinate memories of the other architectures
  * are, by [[bpaccel.MemoryStyle]]: a `SyncReadMem` (module `mem_<rows>x<width>`),
  * or [[bpaccel.RegisteredReadMemory]] with its first output register in the
  * block RAM (ecp5-outreg). The caller tracks which read data are valid.
  */
class BinMemory(p: BinningParams, rows: Int, width: Int) extends Module {
  private val rowBits = log2Ceil(rows).max(1)
  val io = IO(new Bundle {
    val write    = Flipped(Valid(new Bundle { val row = UInt(rowBits.W); val data = UInt(width.W) }))
    val read     = Flipped(Valid(UInt(rowBits.W)))
    val readData = Output(UInt(width.W)) // of the read memoryReadLatency cycles ago
  })
  // The write request through registers (sampled every cycle; the enable has a reset).
  val writeEnable = RegNext(io.write.valid, false.B)
  val writeRow    = RegNext(io.write.bits.row)
  val writeData   = RegNext(io.write.bits.data)
  // No read whose data is used meets a write of its row: a group writes its
  // entries before it sorts them and its order before it reads it, which
  // lets the emitted memory drop the block RAM's collision bypass.
  val readMeetsWrite = RegNext(io.read.valid && writeEnable && io.read.bits === writeRow, false.B)
  // Top-level vals, so that the memory module is named mem_<rows>x<width> (SingleClockMemories, NoCollisionMemories).
  val mem = Option.when(p.memoryStyle == MemoryStyle.Inferred)(SyncReadMem(rows, UInt(width.W)))
  val registeredMem = Option.when(p.memoryStyle == MemoryStyle.Ecp5OutputRegister)(Module(new RegisteredReadMemory(rows, width)))
  for (m <- mem) {
    when(writeEnable) { m.write(writeRow, writeData) }
    io.readData := ShiftRegister(m.read(io.read.bits, io.read.valid), p.memoryOutputStages)
  }
  for (m <- registeredMem) {
    m.io.writeEnable := writeEnable
    m.io.writeRow    := writeRow
    m.io.writeData   := writeData
    m.io.readEnable  := io.read.valid
    m.io.readRow     := io.read.bits
    io.readData := ShiftRegister(m.io.readData, p.memoryOutputStages - 1)
  }
  assert(!readMeetsWrite, "a group memory was read at the row written in the same cycle")
}
