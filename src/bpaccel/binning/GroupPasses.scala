package bpaccel.binning

import chisel3._
import chisel3.util._

/** A read and a write port of a group's cell table (one row per local cell). */
class TablePorts(p: BinningParams) extends Bundle {
  val read     = Valid(UInt(p.localCellBits.W))
  val readData = Input(UInt(p.entryCountWidth.W)) // of the read in the last cycle
  val write    = Valid(new Bundle { val row = UInt(p.localCellBits.W); val data = UInt(p.entryCountWidth.W) })
}

/** Walks a group's local cells of the frame, x fastest, then y, then z. */
class CellScan(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val restart   = Input(Bool())
    val step      = Input(Bool())
    val localDims = Input(Vec(3, UInt((p.cellBits + 1).W)))
    val cell      = Output(UInt(p.localCellBits.W))
    val last      = Output(Bool())
  })
  val at = RegInit(VecInit(Seq.fill(3)(0.U(p.cellBits.W))))
  val ends = (0 until 3).map(a => at(a) === io.localDims(a) - 1.U)
  when(io.step) {
    at(0) := Mux(ends(0), 0.U, at(0) + 1.U)
    when(ends(0)) { at(1) := Mux(ends(1), 0.U, at(1) + 1.U) }
    when(ends(0) && ends(1)) { at(2) := at(2) + 1.U }
  }
  when(io.restart) { at.foreach(_ := 0.U) }
  val fields = (0 until 3).filter(p.localCellBitsPerAxis(_) > 0).reverse.map(a => at(a)(p.localCellBitsPerAxis(a) - 1, 0))
  io.cell := (if (fields.isEmpty) 0.U else Cat(fields))
  io.last := ends.reduce(_ && _)
}

/** Increments table rows, one a cycle, and returns each row's old value a
  * cycle later: the intake's cell counts and the sort's cursors. A row
  * incremented in two cycles in a row takes the value written in the first
  * (forwarded), not the read that met that write.
  */
class TableIncrement(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val in    = Flipped(Valid(UInt(p.localCellBits.W)))
    val table = new TablePorts(p)
    val out   = Valid(new Bundle { val row = UInt(p.localCellBits.W); val old = UInt(p.entryCountWidth.W) })
  })
  val pending   = RegNext(io.in.valid, false.B)
  val row       = RegNext(io.in.bits)
  val lastWrote = RegNext(pending, false.B)
  val lastRow   = RegNext(row)
  val lastValue = Reg(UInt(p.entryCountWidth.W))
  val old = Mux(lastWrote && lastRow === row, lastValue, io.table.readData)
  when(pending) { lastValue := old + 1.U }
  io.table.read.valid       := io.in.valid
  io.table.read.bits        := io.in.bits
  io.table.write.valid      := pending
  io.table.write.bits.row   := row
  io.table.write.bits.data  := old + 1.U
  io.out.valid    := pending
  io.out.bits.row := row
  io.out.bits.old := old
}

/** Reads a group's table over the frame's local cells, one row a cycle in
  * walk order while `advance` holds, from the cycle after `start`; each row
  * comes back a cycle after its read (`returned`). It has the end signals its
  * caller asks for: `last` (the prefix pass) or `running` (the walker).
  */
class TableWalk(p: BinningParams, withLast: Boolean = false, withRunning: Boolean = false) extends Module {
  val io = IO(new Bundle {
    val start     = Input(Bool())
    val localDims = Input(Vec(3, UInt((p.cellBits + 1).W)))
    val advance   = Input(Bool())
    val read      = Valid(UInt(p.localCellBits.W))
    val readData  = Input(UInt(p.entryCountWidth.W))
    val returned  = Valid(new Bundle { val row = UInt(p.localCellBits.W); val data = UInt(p.entryCountWidth.W) })
    val last      = Option.when(withLast)(Output(Bool()))    // this cycle reads the last row
    val running   = Option.when(withRunning)(Output(Bool())) // rows are left to read
  })
  val scan    = Module(new CellScan(p))
  val running = RegInit(false.B)
  val reads   = running && io.advance
  scan.io.localDims := io.localDims
  scan.io.restart   := io.start
  scan.io.step      := reads
  io.read.valid := reads
  io.read.bits  := scan.io.cell
  io.returned.valid     := RegNext(reads, false.B)
  io.returned.bits.row  := RegNext(scan.io.cell)
  io.returned.bits.data := io.readData
  val last    = reads && scan.io.last
  io.last.foreach(_ := last)
  io.running.foreach(_ := running)
  when(last) { running := false.B }
  when(io.start) { running := true.B }
}

/** The prefix pass: turns each cell's count into its first position in the
  * order memory (the entries of the cells before it in the walk). It reads
  * one cell a cycle, from the cycle after `start`, and pulses `next` in its
  * last read's cycle.
  */
class PrefixPass(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val start     = Input(Bool())
    val localDims = Input(Vec(3, UInt((p.cellBits + 1).W)))
    val table     = new TablePorts(p)
    val next      = Output(Bool())
  })
  val walk = Module(new TableWalk(p, withLast = true))
  val sum  = Reg(UInt(p.entryCountWidth.W))
  walk.io.start     := io.start
  walk.io.localDims := io.localDims
  walk.io.advance   := true.B
  walk.io.readData  := io.table.readData
  io.table.read             := walk.io.read
  io.table.write.valid      := walk.io.returned.valid
  io.table.write.bits.row   := walk.io.returned.bits.row
  io.table.write.bits.data  := sum
  when(walk.io.returned.valid) { sum := sum + walk.io.returned.bits.data }
  when(io.start) { sum := 0.U }
  io.next := walk.io.last.get
}

/** The sort pass: reads the group's E entries in memory order, one a cycle
  * from the cycle after `start`, and writes each entry's address into the
  * order memory at its cell's cursor, which it increments: a counting sort of
  * addresses, stable, so a cell's entries stay in stream order. `next`
  * pulses memoryReadLatency + 1 cycles after the last read, in the cycle its
  * cursor write lands (le + 1 cycles after `start` when E = 0).
  */
class SortPass(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val start      = Input(Bool())
    val entries    = Input(UInt(p.entryCountWidth.W))
    val entryRead  = Valid(UInt(p.entryAddrWidth.W))
    val entryCell  = Input(UInt(p.localCellBits.W)) // the cell of the entry read memoryReadLatency cycles ago
    val increment  = Valid(UInt(p.localCellBits.W)) // to the table's TableIncrement
    val cursor     = Flipped(Valid(new Bundle { val row = UInt(p.localCellBits.W); val old = UInt(p.entryCountWidth.W) }))
    val orderWrite = Valid(new Bundle { val row = UInt(p.entryAddrWidth.W); val data = UInt(p.entryAddrWidth.W) })
    val next       = Output(Bool())
  })
  private val le = p.memoryReadLatency
  val running = RegInit(false.B)
  val cycle   = Reg(UInt(log2Ceil(p.groupCapacity + le + 2).W)) // cycles since the first
  val reads   = running && cycle < io.entries
  io.entryRead.valid := reads
  io.entryRead.bits  := cycle(p.entryAddrWidth - 1, 0)
  val arriving = ShiftRegister(reads, le, false.B, true.B)
  val address  = ShiftRegister(cycle(p.entryAddrWidth - 1, 0), le)
  io.increment.valid := arriving
  io.increment.bits  := io.entryCell
  val incremented = RegNext(address) // the address whose cursor comes back now
  val mine        = RegNext(arriving, false.B) // the table increment's result is this pass's
  assert(!mine || io.cursor.valid, "the sort's cursor did not come back")
  // A cursor lies below the group's entry count, so its order-memory row fits entryAddrWidth bits.
  assert(!mine || io.cursor.bits.old < io.entries, "a sort cursor ran past the group's entries")
  io.orderWrite.valid     := mine
  io.orderWrite.bits.row  := io.cursor.bits.old
  io.orderWrite.bits.data := incremented
  io.next := running && cycle === io.entries +& le.U
  when(running) { cycle := cycle + 1.U }
  when(io.next) { running := false.B }
  when(io.start) { running := true.B; cycle := 0.U }
}

/** The walker: reads the sorted table one cell a cycle (each row now holds
  * the end of its cell's entries), clears the row, and queues each cell of two
  * or more entries as (first position, n) for the reader. It reads while the
  * queue's count plus its read in flight is below the queue's depth.
  */
class CellWalker(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val start     = Input(Bool())
    val localDims = Input(Vec(3, UInt((p.cellBits + 1).W)))
    val table     = new TablePorts(p)
    val cells     = Decoupled(new CellRun(p))
    val done      = Output(Bool()) // every cell read and its row cleared
  })
  val queue = Module(new Queue(new CellRun(p), p.cellQueueDepth))
  val walk  = Module(new TableWalk(p, withRunning = true))
  val back  = walk.io.returned
  walk.io.start     := io.start
  walk.io.localDims := io.localDims
  walk.io.advance   := queue.io.count +& back.valid.asUInt < p.cellQueueDepth.U
  walk.io.readData  := io.table.readData
  io.table.read            := walk.io.read
  io.table.write.valid     := back.valid
  io.table.write.bits.row  := back.bits.row
  io.table.write.bits.data := 0.U
  val prevEnd = Reg(UInt(p.entryCountWidth.W))
  val n = back.bits.data - prevEnd
  queue.io.enq.valid      := back.valid && n >= 2.U
  queue.io.enq.bits.start := prevEnd(p.entryAddrWidth - 1, 0)
  queue.io.enq.bits.n     := n
  assert(!queue.io.enq.valid || queue.io.enq.ready, "the walker's cell queue overflowed")
  when(back.valid) { prevEnd := back.bits.data }
  when(io.start) { prevEnd := 0.U }
  io.cells <> queue.io.deq
  io.done := !walk.io.running.get && !back.valid
}
