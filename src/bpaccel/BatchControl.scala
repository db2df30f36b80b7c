package bpaccel

import chisel3._
import chisel3.util._

/** The batch front end: runs the cells of a batch back to back.
  *
  * The host pushes the box counts of a batch's cells on `cells` (a queue of
  * `batchCells` counts), then streams the boxes of all cells in order on the
  * load port. For the cell at the head of the queue this module admits
  * exactly its n boxes, then starts its run through run control, as a
  * host's start(n) would (same checks, same errors, same engine), waits
  * until that run has ended, pops the count and goes on with the next cell.
  * The batch is over when a cell ends and no count is left.
  *
  * Stage 1 does not overlap loading with computing: no box is admitted while
  * a cell runs. Per cell the front end spends one cycle of its own, the one
  * that ends the cell (pops its count); per batch one more, the cycle that
  * accepts its first count (it empties the loader, like a start).
  */
class BatchControl(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val cells      = Flipped(Decoupled(UInt(p.countWidth.W)))
    val hostStart  = Input(Bool()) // the host offers a single start: it wins over a batch's first count
    val runBusy    = Input(Bool()) // run control is running a run
    val loadFire   = Input(Bool()) // a box was accepted
    val active     = Output(Bool()) // a batch is under way
    val begin      = Output(Bool()) // this cycle accepts a batch's first count
    val loadReady  = Output(Bool()) // the current cell wants another box
    val start      = Valid(UInt(p.countWidth.W)) // start the current cell's run (run control is idle)
    val accumulate = Output(Bool()) // the start continues a batch: its counters add to the batch's
    val cellEnd    = Output(Bool()) // the front end's own cycle: the current cell ends
    val cell       = Output(UInt(p.cellTagWidth.W)) // tag of the beats entering the result queue
    val cellsDone  = Output(UInt(32.W))
  })

  val counts    = Module(new Queue(UInt(p.countWidth.W), p.batchCells))
  val active    = RegInit(false.B)
  val running   = RegInit(false.B) // the current cell's run was started
  val admitted  = RegInit(0.U(p.countWidth.W)) // boxes of the current cell accepted so far
  val cellsDone = RegInit(0.U(32.W))

  // Outside a batch a count is taken only when no run is busy and no start is offered.
  val takesCount = active || (!io.runBusy && !io.hostStart)
  counts.io.enq.valid := io.cells.valid && takesCount
  counts.io.enq.bits  := io.cells.bits
  io.cells.ready      := counts.io.enq.ready && takesCount
  io.begin            := io.cells.fire && !active

  val n       = counts.io.deq.bits // the current cell's count: the head stays until the cell ends
  val loading = active && !running
  io.loadReady      := loading && admitted =/= n
  io.start.valid    := loading && admitted === n
  io.start.bits     := n
  io.accumulate     := active && cellsDone =/= 0.U
  when(io.loadFire && loading) { admitted := admitted + 1.U }
  when(io.start.valid) {
    running  := true.B
    admitted := 0.U
  }

  val cellEnd = active && running && !io.runBusy
  counts.io.deq.ready := cellEnd
  io.cellEnd          := cellEnd
  // The deliberate bug of the batch mutant test: cells of fewer than two objects are not counted.
  val counted = if (p.has(Fault.CellCounterSkipsShortCells)) n >= 2.U else true.B
  when(cellEnd) {
    running := false.B
    when(counted) { cellsDone := cellsDone + 1.U }
    when(counts.io.count === 1.U && !counts.io.enq.fire) { active := false.B }
  }
  when(io.begin) {
    active    := true.B
    cellsDone := 0.U
  }

  io.active    := active
  io.cell      := Mux(active, cellsDone(p.cellTagWidth - 1, 0), 0.U)
  io.cellsDone := cellsDone
}
