package bpaccel.shell

import chisel3._
import chisel3.util._

import bpaccel.{Aabb, BroadPhaseAccel, RunRequest, ScheduleBeat}

/** The CELLS command (docs/protocol.md) on a [[BroadPhaseAccel]] (seed or stream).
  *
  * Body: the cell count C, then per cell a header {count, split} and its
  * boxes. Each cell header goes to the core's `cells` port and each box to
  * `load`, through two-entry queues, in stream order: that is the core's
  * batch protocol, so a cell loads while the one before runs. The content
  * is checked before the core sees it (a count above the capacity, a bad
  * split, a key wider than the device's): the core never meets an error.
  *
  * The core ends a batch whenever a cell ends and no count waits (the input
  * ran dry) and begins another with the next count, restarting its cell tags
  * and counters; so the adapter numbers cells itself (cells ended so far in
  * the command: a cell ends only after its last beat left the core) and adds
  * up the core's counters at the end of each of its batches.
  */
class CellsAdapter(p: ShellParams) extends CoreAdapter(p, p.recordWords) {
  val opcode = Protocol.Cells
  private val c = p.cells

  val cancelling = RegNext(io.cancel, false.B)
  // The core and its queues restart on a cancel: nothing of the command is left in them.
  private val datapathReset = (reset.asBool || cancelling)
  val core    = withReset(datapathReset) { Module(new BroadPhaseAccel(c)) }
  val counts  = withReset(datapathReset) { Module(new Queue(new RunRequest(c), 2)) }
  val boxes   = withReset(datapathReset) { Module(new Queue(new Aabb(c.keyWidth), 2)) }
  val results = withReset(datapathReset) { Module(new Queue(new CellResult(p), 2)) }

  object Phase extends ChiselEnum { val Idle, CellCount, CellHeader, Boxes, Finishing = Value }
  val phase      = RegInit(Phase.Idle)
  val cellsTotal = Reg(UInt(32.W))
  val cell       = Reg(UInt(32.W))   // the cell being read
  val boxesLeft  = Reg(UInt(32.W))   // of that cell
  val boxesIn    = Reg(UInt(32.W))
  val cellsEnded = Reg(UInt(32.W))
  val records    = Reg(UInt(32.W))
  private def counter() = Reg(UInt(64.W))
  val intake, runs, issue, stall, pairs = counter()

  // The item at the front of the window.
  private val w         = io.window.words
  private val lastCell  = cell === cellsTotal - 1.U
  io.need := MuxLookup(phase, p.boxWords.U)(Seq(Phase.CellCount -> 1.U, Phase.CellHeader -> 2.U))
  io.last := MuxLookup(phase, false.B)(Seq(
    Phase.CellCount  -> (w(0) === 0.U),
    Phase.CellHeader -> (lastCell && w(0) === 0.U),
    Phase.Boxes      -> (lastCell && boxesLeft === 1.U)
  ))
  io.ready := MuxLookup(phase, false.B)(Seq(
    Phase.CellCount  -> true.B,
    Phase.CellHeader -> counts.io.enq.ready,
    Phase.Boxes      -> boxes.io.enq.ready
  ))
  io.position := cell

  // Content checks, in the order the core would find them.
  private val count = w(0)
  private val split = w(1)
  private val headerError = MuxCase(0.U, Seq(
    (count > c.capacity.U) -> Protocol.coreErrors.find(_.name == "COUNT_OVER_CAPACITY").get.code.U,
    (split =/= 0.U && !c.bipartiteRuns.B) -> Protocol.coreErrors.find(_.name == "SPLIT_UNSUPPORTED").get.code.U,
    (split =/= 0.U && split >= count) -> Protocol.coreErrors.find(_.name == "SPLIT_OUT_OF_RANGE").get.code.U
  ))
  private val box = StreamBox.decode(p, w)
  io.itemError.valid := MuxLookup(phase, false.B)(Seq(Phase.CellHeader -> (headerError =/= 0.U), Phase.Boxes -> box.tooWide))
  io.itemError.bits.code   := Mux(phase === Phase.CellHeader, headerError, Protocol.KeyTooWide.code.U)
  io.itemError.bits.detail := Mux(phase === Phase.CellHeader, cell, boxesIn)

  counts.io.enq.valid      := io.take && phase === Phase.CellHeader
  counts.io.enq.bits.count := count
  counts.io.enq.bits.split := split
  boxes.io.enq.valid       := io.take && phase === Phase.Boxes
  boxes.io.enq.bits        := box.aabb
  assert(!counts.io.enq.valid || counts.io.enq.ready, "a cell header was taken without room")
  assert(!boxes.io.enq.valid || boxes.io.enq.ready, "a box was taken without room")

  private def nextCell(): Unit = {
    cell  := cell + 1.U
    phase := Mux(lastCell, Phase.Finishing, Phase.CellHeader)
  }
  when(io.start) {
    phase := Phase.CellCount
    Seq(cell, boxesIn, cellsEnded, records).foreach(_ := 0.U)
    Seq(intake, runs, issue, stall, pairs).foreach(_ := 0.U)
  }
  when(io.take) {
    switch(phase) {
      is(Phase.CellCount) {
        cellsTotal := count
        phase      := Mux(count === 0.U, Phase.Finishing, Phase.CellHeader)
      }
      is(Phase.CellHeader) {
        boxesLeft := count
        when(count === 0.U)(nextCell()).otherwise(phase := Phase.Boxes)
      }
      is(Phase.Boxes) {
        boxesLeft := boxesLeft - 1.U
        boxesIn   := boxesIn + 1.U
        when(boxesLeft === 1.U)(nextCell())
      }
    }
  }

  // The core: cells and boxes in, result beats out; never a single start.
  core.io.cells <> counts.io.deq
  core.io.load <> boxes.io.deq
  core.io.start.valid := false.B
  core.io.start.bits  := DontCare
  results.io.enq.valid       := core.io.result.valid
  results.io.enq.bits.beat.iBase := core.io.result.bits.iBase
  results.io.enq.bits.beat.jBase := core.io.result.bits.jBase
  results.io.enq.bits.beat.mask  := core.io.result.bits.mask
  results.io.enq.bits.cell   := cellsEnded
  core.io.result.ready       := results.io.enq.ready

  // A cell has ended when the core's count of ended cells moves (it restarts from 0 with each of its batches).
  private val cellsDone = core.io.status.cellsDone
  when(cellsDone =/= RegNext(cellsDone, 0.U) && cellsDone =/= 0.U) { cellsEnded := cellsEnded + 1.U }
  // Each of the core's batches adds its counters once they are final: in the cycle after it ends.
  private val batchWas = RegNext(core.io.status.batch, false.B)
  // The core tags beats with their cell's index in its own batch: the adapter's numbering must agree.
  private val tag       = cellsEnded(c.cellTagWidth - 1, 0)
  private val batchBase = RegEnable(tag, !batchWas && core.io.status.batch)
  assert(!core.io.result.valid || core.io.result.bits.cell === tag - batchBase,
    "the adapter's cell numbering disagrees with the core's cell tags")
  when(batchWas && !core.io.status.batch) {
    val k = core.io.counters
    intake := intake + k.loadCycles
    runs   := runs + k.cycles
    issue  := issue + k.issueCycles
    stall  := stall + k.stallCycles
    pairs  := pairs + k.hits
  }

  // Records: {j, i} or i, j; the cell's index in the command; the hit mask.
  private val r    = results.io.deq.bits
  private val idx  = if (p.indexWords == 1) Seq(Cat(r.beat.jBase.pad(16), r.beat.iBase.pad(16))) else Seq(r.beat.iBase.pad(32), r.beat.jBase.pad(32))
  private val mask = r.beat.mask.pad(32 * p.maskWords)
  io.records.valid      := results.io.deq.valid && !cancelling // none after a cancel: the summary counts them all
  io.records.bits.words := VecInit(idx ++ Seq(r.cell) ++ (0 until p.maskWords).map(i => mask(32 * i + 31, 32 * i)))
  io.records.bits.count := p.recordWords.U
  results.io.deq.ready  := io.records.ready
  when(io.records.fire) { records := records + 1.U }

  // The summary: at once after a cancel, else when every cell has ended and its records are out.
  val done = phase === Phase.Finishing && cellsEnded === cellsTotal && !core.io.status.batch && !batchWas &&
    !results.io.deq.valid
  io.summary.valid             := phase =/= Phase.Idle && (cancelling || done)
  io.summary.bits.records      := records
  io.summary.bits.boxes        := boxesIn
  io.summary.bits.cells        := cellsEnded
  io.summary.bits.runCycles    := runs
  io.summary.bits.intakeCycles := intake
  io.summary.bits.issueCycles  := issue
  io.summary.bits.stallCycles  := stall
  io.summary.bits.pairs        := pairs
  io.summary.bits.error        := 0.U.asTypeOf(new ItemError) // its checks come before the core: each is an itemError
  when(io.summary.fire) { phase := Phase.Idle }
  when(io.cancel) { phase := Phase.Finishing }
}

/** A result beat of the core with its cell's index in the command. */
class CellResult(p: ShellParams) extends Bundle {
  val beat = new ScheduleBeat(p.cells)
  val cell = UInt(32.W)
}

/** A box as the stream carries it (docs/protocol.md). */
object StreamBox {
  class Decoded(keyWidth: Int) extends Bundle {
    val aabb    = new Aabb(keyWidth)
    val tooWide = Bool() // a key's slot has bits set above the key width
  }

  /** The six keys of the box in `words`: min x, y, z, max x, y, z, each a
    * half-word (low half first) or a word.
    */
  def decode(p: ShellParams, words: Seq[UInt]): Decoded = {
    val slots: Seq[UInt] =
      if (p.keySlotBits == 32) words.take(6)
      else words.take(3).flatMap(w => Seq(w(15, 0), w(31, 16)))
    val out = Wire(new Decoded(p.core.keyWidth))
    for (a <- 0 until 3) {
      out.aabb.min(a) := slots(a)(p.core.keyWidth - 1, 0)
      out.aabb.max(a) := slots(3 + a)(p.core.keyWidth - 1, 0)
    }
    out.tooWide := (if (p.core.keyWidth == p.keySlotBits) false.B
                    else slots.map(s => s(p.keySlotBits - 1, p.core.keyWidth) =/= 0.U).reduce(_ || _))
    out
  }
}
