package bpaccel

import chisel3._
import chisel3.util._

/** The batch front end: runs the cells of a batch back to back.
  *
  * The host pushes the box counts of a batch's cells on `cells` (a queue of
  * `batchCells` counts), then streams the boxes of all cells in order on the
  * load port. The cell at the head of the queue is the one being loaded:
  * this module admits exactly its n boxes, then starts its run through run
  * control, as a host's start(n) would (same checks, same errors, same
  * engine), once the cell before it has ended. The batch is over when a cell
  * ends and no count is left.
  *
  * Where the architecture overlaps loads ([[AccelParams.overlapsLoads]]),
  * the head moves on to the next count as soon as its cell starts, so the
  * next cell loads while the current one runs: its boxes go to the memory's
  * other bank, and objects 0 .. m to the engine's head registers, which the
  * start copied into the B window and A block before. Without overlap the
  * head takes the next count only when its cell has ended, and no box is
  * admitted while a cell runs.
  *
  * Per cell the front end spends one cycle of its own, the one that ends
  * the cell; per batch one more, the cycle that accepts its first count (it
  * empties the loader, like a start).
  */
class BatchControl(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val cells      = Flipped(Decoupled(new RunRequest(p)))
    val hostStart  = Input(Bool()) // the host offers a single start: it wins over a batch's first count
    val runBusy    = Input(Bool()) // run control is running a run
    val loadFire   = Input(Bool()) // a box was accepted
    val active     = Output(Bool()) // a batch is under way
    val begin      = Output(Bool()) // this cycle accepts a batch's first count
    val take       = Valid(new CellCount(p)) // the head takes this count: the loader starts the cell's numbering
    val loadReady  = Output(Bool()) // the current cell wants another box
    val start      = Valid(new RunRequest(p)) // start the current cell's run (run control is idle)
    val accumulate = Output(Bool()) // the start continues a batch: its counters add to the batch's
    val cellEnd    = Output(Bool()) // the front end's own cycle: the current cell ends
    val cell       = Output(UInt(p.cellTagWidth.W)) // tag of the beats entering the result queue
    val cellsDone  = Output(UInt(32.W))
  })

  // The queue's head is held in registers of its own (`current`), so that
  // load-ready, which fans out to the engine's window enables, is a
  // flip-flop, not a count read from the queue's memory and compared with
  // the boxes admitted (docs/fpga.md).
  // The tail flows through when empty, so head + tail hold `batchCells`
  // counts and every count reaches the head in the cycle it would have
  // reached the head of a single queue.
  val current   = Reg(UInt(p.countWidth.W)) // the head cell's count; valid while `loading`
  val currentSplit = Reg(UInt(p.countWidth.W)) // and its split
  val left      = Reg(UInt(p.countWidth.W)) // boxes of the head cell still to admit
  val wantsBox  = RegInit(false.B) // loading, and left =/= 0: the registered load-ready
  val active    = RegInit(false.B)
  val loading   = RegInit(false.B) // the head holds a cell that has not started
  val running   = RegInit(false.B) // a cell was started and has not ended
  val cellsDone = RegInit(0.U(32.W))

  // Outside a batch a count is taken only when no run is busy and no start is
  // offered. With batchCells = 1 the head is the whole queue: no count is
  // taken while it is in use.
  val takesFirstCount = !io.runBusy && !io.hostStart
  val takesCount = (active && (p.batchCells > 1).B) || takesFirstCount
  val tailIn     = Wire(Decoupled(new CellCount(p)))
  tailIn.valid   := io.cells.valid && takesCount
  tailIn.bits    := CellCount(p, io.cells.bits)
  io.cells.ready := tailIn.ready && takesCount
  val tail = Queue(tailIn, p.batchCells - 1, flow = true) // no entries: a wire
  // Whether the tail offers a count, from a register (the queue held one at
  // the cycle's start) or the count flowing through, not the queue's own
  // valid, which compares its pointers: with overlapped loads every count
  // taken clears the loader and the engine.
  val tailHolds = RegInit(false.B)
  val tailValid = tailHolds || tailIn.valid
  assert(tailValid === tail.valid, "the tail queue's registered non-empty flag is wrong")
  val tailFire = tailValid && tail.ready
  // Outside a batch the tail is empty and a count flows straight to the head,
  // so the first count is taken without asking the tail queue: its pointers
  // were the start of stream m = 64's critical path (through `begin` and the
  // loader's clear to the loaded count).
  assert(active || tailIn.ready, "the batch front end's tail queue held a count outside a batch")
  io.begin := io.cells.valid && !active && takesFirstCount

  io.loadReady   := wantsBox
  io.start.valid := loading && !wantsBox && !running
  io.start.bits.count := current
  io.start.bits.split := currentSplit
  // A register, not cellsDone =/= 0: a 32-bit test in front of every counter's enable was the next m = 8 critical path.
  val cellEnded = RegInit(false.B) // a cell of this batch has ended
  io.accumulate := active && cellEnded
  when(io.loadFire && wantsBox) {
    left     := left - 1.U
    wantsBox := left =/= 1.U
  }

  val cellEnd = active && running && !io.runBusy
  // The head takes the next count when it is free: a batch's first; then,
  // with overlap, when its cell starts (or later, if the count comes later),
  // else when the running cell ends.
  val headFree =
    if (p.overlapsLoads && !p.has(Fault.BatchLoadsInSeries)) !loading || io.start.valid
    else !loading && (!running || cellEnd)
  tail.ready := !active || headFree
  io.take.valid := tailFire
  io.take.bits  := tail.bits
  // Counts held in the tail queue, kept beside it: an arriving count is
  // stored unless it flows straight to the head (queue empty, taken at once).
  val tailCount = RegInit(0.U(log2Ceil(p.batchCells).W))
  val stored    = tailIn.fire && !(tailFire && !tailHolds)
  val unstored  = tailFire && tailHolds
  val tailCountNext = tailCount + stored.asUInt - unstored.asUInt
  tailCount := tailCountNext
  tailHolds := tailCountNext =/= 0.U
  when(io.start.valid) {
    running := true.B
    loading := false.B
  }
  when(tailFire) {
    current  := tail.bits.count
    currentSplit := tail.bits.split
    left     := tail.bits.count
    wantsBox := tail.bits.nonEmpty
    loading  := true.B
  }
  io.cellEnd := cellEnd
  // The deliberate bug of the batch mutant test: cells of fewer than two objects are not counted.
  val counted = if (p.has(Fault.CellCounterSkipsShortCells)) RegEnable(current >= 2.U, io.start.valid) else true.B
  when(cellEnd) {
    running   := false.B
    cellEnded := true.B
    when(counted) { cellsDone := cellsDone + 1.U }
    when(!loading && !tailValid) { active := false.B }
  }
  when(io.begin) {
    active    := true.B
    cellsDone := 0.U
    cellEnded := false.B
  }

  io.active    := active
  io.cell      := Mux(active, cellsDone(p.cellTagWidth - 1, 0), 0.U)
  io.cellsDone := cellsDone
}
