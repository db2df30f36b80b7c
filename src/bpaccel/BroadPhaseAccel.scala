package bpaccel

import chisel3._
import chisel3.util._

/** Top level, shared by both architectures: loader, run control, the
  * architecture's engine and the result queue.
  *
  * Protocol: load boxes through `load` (object indices count from 0 in load
  * order), then send n on `start` (with split 0; or na for a bipartite
  * run, see [[RunRequest]]). Results arrive on `result` as beats of one
  * schedule cycle each (see [[ResultBeat]]); `status.done` rises once every
  * beat has been taken. A start resets the load pointer, so each run loads
  * its own boxes. A load beyond the capacity or a start with n larger than
  * the capacity or than the boxes loaded ends the run at once with an error
  * and no results, never with a partial answer.
  *
  * Batches: push the box counts of up to `batchCells` cells on `cells`, then
  * stream all their boxes on `load`, in cell order, each cell in index
  * order; [[BatchControl]] runs the cells one after the other,
  * loading the next while the current one runs where it can, and result
  * beats carry their cell's index. A start is refused while a batch is under way.
  *
  * Back-pressure by credits: the engine only issues a schedule cycle when the
  * result queue is sure to have room for it once it leaves the pipeline, so
  * the pipeline after the issue never stalls and no hit is ever dropped or
  * duplicated.
  */
class BroadPhaseAccel(val p: AccelParams) extends Module {
  override def desiredName: String = BroadPhaseAccel.topName
  val io = IO(new Bundle {
    val load     = Flipped(Decoupled(new Aabb(p.keyWidth)))
    val start    = Flipped(Decoupled(new RunRequest(p)))
    val cells    = Flipped(Decoupled(new RunRequest(p)))
    val result   = Decoupled(new ResultBeat(p))
    val status   = Output(new AccelStatus(p))
    val counters = Output(new AccelCounters(p))
    val info     = Output(new AccelInfo)
    val debug    = if (p.debugPort) Some(Output(new DebugProbe(p))) else None
  })

  val loader  = Module(new Loader(p))
  val control = Module(new RunControl(p))
  val batch   = Module(new BatchControl(p))
  val engine  = Module(p.arch.engine(p))
  // A beat that meets an empty queue and a ready consumer passes in the same cycle.
  val queue = Module(new Queue(new ResultBeat(p), p.resultQueueDepth, flow = true))

  batch.io.cells <> io.cells
  batch.io.hostStart := io.start.valid
  batch.io.runBusy   := control.io.status.busy
  batch.io.loadFire  := io.load.fire

  // The run control's start: the host's outside a batch, the front end's within one.
  val start = Wire(Decoupled(new RunRequest(p)))
  start.valid    := Mux(batch.io.active, batch.io.start.valid, io.start.valid)
  start.bits     := Mux(batch.io.active, batch.io.start.bits, io.start.bits)
  io.start.ready := start.ready && !batch.io.active
  assert(!batch.io.start.valid || start.ready, "the batch front end started a cell while a run was busy")
  // Starts clear the loader, and so does a batch's first count: its first
  // box is object 0. With overlapped loads every count the head takes starts
  // its cell's numbering while the last cell may still run.
  val clear = start.fire || (if (p.overlapsLoads) batch.io.take.valid else batch.io.begin)

  // A start or a batch's first count in the same cycle wins, so a box is never loaded into the next run by accident.
  // `offered` is the same without that term, for the engine's look-aheads,
  // so that the host's start and count do not reach the head chain's enable
  // copies through the load port's ready.
  val loadOpen = Mux(batch.io.active, batch.io.loadReady, !control.io.status.busy)
  io.load.ready := loadOpen && (batch.io.active || !io.start.valid && !io.cells.valid)
  loader.io.offered    := io.load.valid && loadOpen
  loader.io.load.valid := io.load.fire
  loader.io.load.bits  := io.load.bits
  loader.io.clear      := clear

  control.io.start <> start
  control.io.accumulate    := batch.io.accumulate
  control.io.batchBegin    := batch.io.begin
  control.io.batchActive   := batch.io.active
  control.io.frontEndCycle := batch.io.cellEnd
  control.io.loadFire := io.load.fire
  control.io.loaded   := loader.io.loaded
  control.io.overflow := loader.io.overflow

  engine.io.write   := loader.io.write
  engine.io.writeOffered := loader.io.writeOffered
  engine.io.loadClear    := clear
  engine.io.prepare.valid := start.fire
  engine.io.prepare.bits  := start.bits
  engine.io.headPad       := loader.io.headPad
  engine.io.launch  := control.io.launch
  // Credits: result-queue entries neither occupied nor claimed by a cycle in
  // flight, kept in a register so that no compare of the queue's pointers
  // (count + in flight + 1 < depth) sits in front of the engine's enable
  // look-ahead.
  // Occupied + claimed grows by at most one a cycle, so two credits now mean
  // room for one more issue in the next cycle.
  val credits = RegInit(creditedEntries.U(log2Ceil(creditedEntries + 1).W))
  credits := credits - engine.io.activity.issued.asUInt + engine.io.activity.retired.asUInt -
    queue.io.enq.fire.asUInt + queue.io.deq.fire.asUInt
  assert(
    credits === creditedEntries.U -& queue.io.count -& engine.io.activity.inFlight,
    "the result queue's credits do not match its count and the cycles in flight"
  )
  engine.io.room := credits >= 2.U
  control.io.engine := engine.io.activity

  val beat = engine.io.out
  queue.io.enq.valid := beat.valid && engine.io.outHit
  queue.io.enq.bits.iBase := beat.bits.iBase
  queue.io.enq.bits.jBase := beat.bits.jBase
  queue.io.enq.bits.mask  := beat.bits.mask
  queue.io.enq.bits.cell  := batch.io.cell
  assert(!queue.io.enq.valid || queue.io.enq.ready, BroadPhaseAccel.ResultQueueOverflow)
  io.result <> queue.io.deq
  if (p.has(Fault.DropBeatWhenNotReady)) queue.io.deq.ready := true.B

  // The popcount gets its own register, apart from the 64-bit add, and the
  // engine counts groups of lanes beside the mask, so only their sum is
  // left here. The count still lands by the time done rises, which is at
  // least one cycle after the last beat was queued.
  control.io.queuedHits := Pipe(queue.io.enq.fire, Engine.sumHitCounts(p.m, engine.io.outHitCounts))
  control.io.queueEmpty       := queue.io.count === 0.U

  io.status.error     := control.io.status.error
  io.status.loaded    := control.io.status.loaded
  io.status.busy      := control.io.status.busy || batch.io.active
  io.status.done      := control.io.status.done && !batch.io.active
  io.status.batch     := batch.io.active
  io.status.cellsDone := batch.io.cellsDone
  io.counters := control.io.counters

  io.info := AccelInfo(p)

  io.debug.foreach(_ := engine.io.probe.get)

  /** Result-queue entries the credit check counts on (one too many with that mutant's fault). */
  private def creditedEntries: Int = p.resultQueueDepth + (if (p.has(Fault.CreditOneTooMany)) 1 else 0)
}

object BroadPhaseAccel {
  /** The top module's name in the emitted Verilog. */
  val topName = "BroadPhaseAccel"

  /** The message of the design's own check that credits never let a beat meet a full result queue. */
  val ResultQueueOverflow = "result queue overflow: credit accounting is broken"
}
