package bpaccel

import chisel3._

/** One coordinate memory in the configuration's [[MemoryStyle]]: the one
  * place that tells the styles apart. A write lands at the next clock edge;
  * a read's data comes [[latency]] cycles after its row, the memory's own
  * output register included where the style has one (and then holds until
  * the next read's data arrives).
  *
  *  - Inferred: a `SyncReadMem`, which firtool emits as module
  *    `mem_<rows>x<width>` and FPGA tools map to block RAM.
  *  - Ecp5OutputRegister: a [[RegisteredReadMemory]], which the FPGA flow
  *    builds from DP16KD with the output register on.
  */
class CoordinateMemory(style: MemoryStyle, rows: Int, width: Int) {
  val latency: Int = style.readLatency

  private val inferred = Option.when(style == MemoryStyle.Inferred)(SyncReadMem(rows, UInt(width.W)).suggestName("mem"))
  private val registered = Option.when(style == MemoryStyle.Ecp5OutputRegister)(
    Module(new RegisteredReadMemory(rows, width)).suggestName("mem"))

  def write(enable: Bool, row: UInt, data: UInt): Unit = {
    for (mem <- inferred) when(enable) { mem.write(row, data) }
    for (mem <- registered) {
      mem.io.writeEnable := enable
      mem.io.writeRow    := row
      mem.io.writeData   := data
    }
  }

  def read(enable: Bool, row: UInt): UInt =
    inferred.map(_.read(row, enable)).getOrElse {
      val mem = registered.get
      mem.io.readEnable := enable
      mem.io.readRow    := row
      mem.io.readData
    }
}
