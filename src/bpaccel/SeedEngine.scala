package bpaccel

import chisel3._
import chisel3.util._

/** The seed's architecture: striped coordinate buffers, the A/B address
  * sequencer, the rotator and the comparator array.
  *
  * Pipeline, one schedule cycle per clock when unstalled:
  * issue -> memory read -> memory output registers -> rotator register ->
  * comparator register -> AND register. The sequencer only issues when the top level
  * grants a credit (`advance`), so the pipeline itself never stalls.
  *
  * Each memory has a single read port, busy with the B window every cycle, so
  * the A block is never read: it sits in registers (`aBlock`). The next
  * block's A objects pass through the B ports during the current block (B port
  * k reads object (b+1)*m+k in the block's cycle k, see [[AddressSequencer]]),
  * and `aNext(k)` captures memory k's data there, after the output registers.
  * `aBlock` takes `aNext` when a block's first cycle reaches that stage, so
  * each capture lands before the block that uses it and after the block
  * that uses the previous contents: no extra port, no extra cycle.
  *
  * Block 0's A objects 0 .. m-1 never pass a B window. While loading, the B
  * ports are free: the cycle after object k < m reaches its row (memory k,
  * row 0; the write port is registered, so two cycles after the load port
  * took it), B port k reads it back and `aNext(k)` captures it the same way.
  * A run starts at the earliest one cycle after its last load, so its first
  * issue comes two cycles after that load at the earliest. Only the
  * read-back of the last box loaded can meet it; the issue's read wins, and
  * nothing is lost: that read-back happens then only when every box loaded
  * is in block 0, and the last of them is never an A object that is
  * compared (no object follows it). Every other read-back lands before
  * block 0's first cycle does.
  *
  * No A register has a multiplexer in front of it: `aNext(k)` loads from
  * memory k's read data, `aBlock` from `aNext` (clock enables only).
  */
class SeedEngine(p: AccelParams) extends Engine(p) {
  private val m = p.m

  val buffer    = Module(new CoordBuffer(p))
  val sequencer = Module(new AddressSequencer(p))
  val compare   = Module(new ComparatorArray(p))

  buffer.io.write.valid     := io.write.valid
  buffer.io.write.bits.lane := io.write.bits.lane
  buffer.io.write.bits.row  := io.write.bits.row
  buffer.io.write.bits.box  := io.write.bits.box

  sequencer.io.start   := io.launch
  sequencer.io.advance := advance
  val issue = sequencer.io.issue

  // The writes as the memories see them, CoordBuffer.writeLatency cycles later.
  val memoryWrite = Wire(Valid(UInt(m.W))) // bits: block 0's one-hot lane
  memoryWrite.valid := ShiftRegister(io.write.valid, CoordBuffer.writeLatency, false.B, true.B)
  memoryWrite.bits  := ShiftRegister(Mux(io.write.valid, io.write.bits.firstBlockLane, 0.U), CoordBuffer.writeLatency, 0.U, true.B)
  // Read back block 0's A objects the cycle after they reach their row.
  val loadRead = RegNext(memoryWrite.bits, 0.U(m.W))
  // readsNeverMeetWrites: no read whose data is used meets a write of the same
  // memory row in the same cycle, which lets the emitted memories drop the
  // block RAM's collision bypass (NoCollisionMemories). Runs never overlap
  // the memories' writes, and block 0's read-back comes the cycle after its write.
  assert(!(memoryWrite.valid && sequencer.io.active), "a box was written while a run read the memories")
  for (k <- 0 until m)
    assert(!(loadRead(k) && memoryWrite.bits(k)), "a block-0 read-back met a write of its row")
  // While idle every port reads row 0. The read enable is always on: a
  // read's data is used only where a capture or a schedule stage says so,
  // and an enable computed from the run state and the read-backs would
  // reach the read enables of all 6m block RAMs.
  val readRows = VecInit(issue.bits.bRows.map(r => Mux(sequencer.io.active, r, 0.U)))
  buffer.io.readEnable := true.B
  buffer.io.rows       := readRows

  /** The object each memory's read port reads (debug tags only). */
  private val portObjects = VecInit(Seq.tabulate(m)(k => (readRows(k) * m.U + k.U)(p.indexWidth - 1, 0)))
  private def tags(v: Vec[UInt]): Vec[UInt] = if (p.debugPort) v else VecInit(Seq.fill(m)(0.U(0.W)))
  private val tagWidth = if (p.debugPort) p.indexWidth else 0

  class Meta extends Bundle {
    val iBase      = UInt(p.indexWidth.W)
    val jBase      = UInt(p.indexWidth.W)
    val laneMask   = UInt(m.W)
    val rotate     = UInt(p.laneWidth.W)
    val blockStart = Bool()
    val probeJ     = Vec(m, UInt(tagWidth.W)) // the B objects each lane sees (debug port only)
  }
  val meta = Wire(new Meta)
  meta.iBase      := issue.bits.iBase
  meta.jBase      := issue.bits.jBase
  meta.laneMask   := issue.bits.laneMask
  meta.rotate     := issue.bits.rotate
  meta.blockStart := issue.bits.blockStart
  // Derived from the row addresses given to the memories and the rotator's selection, not from jBase.
  meta.probeJ := (if (p.debugPort) Rotator(portObjects, issue.bits.rotate) else tags(portObjects))

  /** Which memories' read data the A registers take, and (debug) which objects that data is. */
  class Capture extends Bundle {
    val lanes = UInt(m.W)
    val tags  = Vec(m, UInt(tagWidth.W))
  }
  val capture = Wire(new Capture)
  // While a run is active its rows are read: a read-back that meets it is dropped (see above).
  capture.lanes := Mux(sequencer.io.active, Mux(issue.valid, issue.bits.capture, 0.U), loadRead)
  capture.tags  := tags(portObjects)

  // Memory read (1 cycle), then the memory output registers; the buffer's
  // data comes the memory style's readLatency cycles after the read (the
  // first output register may sit inside the memories).
  val memoryStages = Seq.iterate(
    (Pipe(issue.valid, meta), Pipe(issue.valid || loadRead.orR, capture)),
    p.memoryOutputStages + 1
  ) { case (at, cap) => (Pipe(at), Pipe(cap)) }
  val memData = Seq.iterate(buffer.io.data, p.memoryOutputStages + 2 - p.memoryStyle.readLatency)(RegNext(_)).last
  val (atBuffered, captureAt) = memoryStages.last

  // The A blocks, captured from the read data.
  val aNext     = Reg(Vec(m, new Aabb(p.keyWidth)))
  val aNextTag  = Reg(Vec(m, UInt(tagWidth.W)))
  val aBlock    = Reg(Vec(m, new Aabb(p.keyWidth)))
  val aBlockTag = Reg(Vec(m, UInt(tagWidth.W)))
  when(atBuffered.valid && atBuffered.bits.blockStart) {
    aBlock    := aNext
    aBlockTag := aNextTag
  }
  for (k <- 0 until m) when(captureAt.valid && captureAt.bits.lanes(k)) {
    aNext(k)    := memData(k)
    aNextTag(k) := captureAt.bits.tags(k)
  }

  // Rotator, registered; the A block is already a register.
  val rotatedB  = RegNext(Rotator(memData, atBuffered.bits.rotate))
  val atRotated = Pipe(atBuffered)
  // Comparators, registered; then the AND gates and any-hit, registered (as the stream).
  compare.io.a := aBlock
  compare.io.b := rotatedB
  val compared   = RegNext(compare.io.compares)
  val atCompared = Pipe(atRotated)
  val hits = Engine.hitRegisters(m, ComparatorArray.hits(compared) & atCompared.bits.laneMask)
  val atAnd  = Pipe(atCompared)
  val probeI = RegNext(RegNext(aBlockTag))

  val stages = memoryStages.map(_._1) ++ Seq(atRotated, atCompared, atAnd)
  require(stages.length == p.pipelineLatency)

  io.activity.active   := sequencer.io.active
  io.activity.issued   := issue.valid
  io.activity.stalled  := sequencer.io.active && !issue.valid
  io.activity.inFlight := PopCount(stages.map(_.valid))
  io.activity.retired  := stages.last.valid

  emit(atAnd.valid, atAnd.bits.iBase, atAnd.bits.jBase, atAnd.bits.laneMask, probeI, atAnd.bits.probeJ, hits)
}
