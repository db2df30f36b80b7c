package bpaccel

import chisel3._
import chisel3.util._

/** Top level, shared by both architectures: loader, run control, the
  * architecture's engine and the result queue.
  *
  * Protocol: load boxes through `load` (object indices count from 0 in load
  * order), then send n on `start`. Results arrive on `result` as beats of one
  * schedule cycle each (see [[ResultBeat]]); `status.done` rises once every
  * beat has been taken. A start resets the load pointer, so each run loads
  * its own boxes. A load beyond the capacity or a start with n larger than
  * the capacity or than the boxes loaded ends the run at once with an error
  * and no results, never with a partial answer.
  *
  * Back-pressure by credits: the engine only issues a schedule cycle when the
  * result queue is sure to have room for it once it leaves the pipeline, so
  * the pipeline after the issue never stalls and no hit is ever dropped or
  * duplicated.
  */
class BroadPhaseAccel(val p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val load     = Flipped(Decoupled(new Aabb(p.keyWidth)))
    val start    = Flipped(Decoupled(UInt(p.countWidth.W)))
    val result   = Decoupled(new ResultBeat(p))
    val status   = Output(new AccelStatus(p))
    val counters = Output(new AccelCounters(p))
    val info     = Output(new AccelInfo)
    val debug    = if (p.debugPort) Some(Output(new DebugProbe(p))) else None
  })

  val loader  = Module(new Loader(p))
  val control = Module(new RunControl(p))
  val engine = p.arch match {
    case Arch.Seed   => Module(new SeedEngine(p))
    case Arch.Stream => Module(new StreamEngine(p))
  }
  // A beat that meets an empty queue and a ready consumer passes in the same cycle.
  val queue = Module(new Queue(new ResultBeat(p), p.resultQueueDepth, flow = true))

  // A start in the same cycle wins, so a box is never loaded into the next run by accident.
  io.load.ready       := !control.io.status.busy && !io.start.valid
  loader.io.load.valid := io.load.fire
  loader.io.load.bits  := io.load.bits
  loader.io.clear      := io.start.fire

  control.io.start <> io.start
  control.io.loadFire := io.load.fire
  control.io.loaded   := loader.io.loaded
  control.io.overflow := loader.io.overflow

  engine.io.write   := loader.io.write
  engine.io.clear   := io.start.fire
  engine.io.launch  := control.io.launch
  // Credits, registered so that no adder sits before the engine's enables:
  // queue count + cycles in flight grows by at most one a cycle, so room for
  // one more last cycle means room now.
  engine.io.advance := RegNext(
    queue.io.count +& engine.io.activity.inFlight +& 1.U < creditedEntries.U,
    false.B
  )
  control.io.engine := engine.io.activity

  val beat = engine.io.out
  queue.io.enq.valid := beat.valid && beat.bits.mask.orR
  queue.io.enq.bits  := beat.bits
  assert(!queue.io.enq.valid || queue.io.enq.ready, "result queue overflow: credit accounting is broken")
  io.result <> queue.io.deq
  if (p.has(Fault.DropBeatWhenNotReady)) queue.io.deq.ready := true.B

  // The popcount gets its own register: at m = 32 popcount + 64-bit add was
  // the critical path (80.7 MHz). The count still lands by the time done
  // rises, which is at least one cycle after the last beat was queued.
  control.io.queuedHits := Pipe(queue.io.enq.fire, PopCount(beat.bits.mask))
  control.io.queueEmpty       := queue.io.count === 0.U

  io.status   := control.io.status
  io.counters := control.io.counters

  io.info.arch              := p.arch.id.U
  io.info.m                 := p.m.U
  io.info.capacity          := p.capacity.U
  io.info.keyWidth          := p.keyWidth.U
  io.info.runOverheadCycles := p.runOverheadCycles.U
  io.info.readLatency       := (if (p.arch == Arch.Stream) p.readLatency else 0).U

  io.debug.foreach(_ := engine.io.probe.get)

  /** Result-queue entries the credit check counts on (one too many with that mutant's fault). */
  private def creditedEntries: Int = p.resultQueueDepth + (if (p.has(Fault.CreditOneTooMany)) 1 else 0)
}
