package bpaccel

import chisel3._
import chisel3.util._

/** Top level: buffers, sequencer, rotator, comparator array, result queue.
  *
  * Protocol: load boxes through `load` (object indices count from 0 in load
  * order), then send n on `start`. Results arrive on `result` as beats of one
  * schedule cycle each (see [[ResultBeat]]); `status.done` rises once every
  * beat has been taken. A start resets the load pointer, so each run loads
  * its own boxes. A load beyond the capacity or a start with n larger than
  * the capacity or than the boxes loaded ends the run at once with an error
  * and no results, never with a partial answer.
  *
  * Back-pressure: the sequencer only issues a cycle when the result queue is
  * sure to have room for it once it leaves the pipeline, so the pipeline
  * itself never stalls and no hit is ever dropped or duplicated.
  *
  * Pipeline, one schedule cycle per clock when unstalled:
  * issue -> memory read -> memory output registers -> rotator register ->
  * comparator/AND register -> result queue (flow-through).
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

  private val m = p.m

  val buffer    = Module(new CoordBuffer(p))
  val sequencer = Module(new AddressSequencer(p))
  val compare   = Module(new ComparatorArray(p))
  val queue     = Module(new ResultQueue(p))

  // ---- control state ----
  val busy     = RegInit(false.B)
  val done     = RegInit(false.B)
  val error    = RegInit(AccelError.None.U(AccelError.width.W))
  val loaded   = RegInit(0.U(p.countWidth.W))
  val loadLane = RegInit(0.U(p.laneWidth.W))
  val loadRow  = RegInit(0.U(p.rowWidth.W))
  val overflow = RegInit(false.B)

  val cycles      = RegInit(0.U(p.counterWidth.W))
  // Load cycles of the run being loaded: from its first accepted box to the
  // cycle that accepts its start, gaps included, since the device belongs to
  // that run from its first box on. Published in loadCycles at the start.
  val loading       = RegInit(false.B)
  val loadingCycles = RegInit(0.U(p.counterWidth.W))
  val loadCycles    = RegInit(0.U(p.counterWidth.W))
  val issueCycles = RegInit(0.U(p.counterWidth.W))
  val stallCycles = RegInit(0.U(p.counterWidth.W))
  val hits        = RegInit(0.U(p.counterWidth.W))
  val drainCycles = RegInit(0.U(log2Ceil(p.runOverheadCycles + 1).W))

  io.start.ready := !busy
  // A start in the same cycle wins, so a box is never loaded into the next run by accident.
  io.load.ready := !busy && !io.start.valid

  // ---- loading ----
  val full = loaded === p.capacity.U
  buffer.io.write.valid     := io.load.fire && !full
  buffer.io.write.bits.lane := loadLane
  buffer.io.write.bits.row  := loadRow
  buffer.io.write.bits.box  := io.load.bits
  when(io.load.fire) {
    when(full) {
      overflow := true.B
      error    := AccelError.LoadOverflow.U
    }.otherwise {
      loaded := loaded + 1.U
      if (m == 1) loadRow := loadRow + 1.U
      else {
        val lastLane = loadLane === (m - 1).U
        loadLane := Mux(lastLane, 0.U, loadLane + 1.U)
        when(lastLane) { loadRow := loadRow + 1.U }
      }
    }
  }

  when(io.load.fire && !loading) {
    loading       := true.B
    loadingCycles := 1.U
  }.elsewhen(loading) {
    loadingCycles := loadingCycles + 1.U
  }

  // ---- starting ----
  sequencer.io.start.valid := false.B
  sequencer.io.start.bits  := io.start.bits
  when(io.start.fire) {
    val n = io.start.bits
    loaded      := 0.U
    loadLane    := 0.U
    loadRow     := 0.U
    overflow    := false.B
    cycles      := 0.U
    loadCycles  := Mux(loading, loadingCycles + 1.U, 1.U) // + the start cycle itself
    loading     := false.B
    issueCycles := 0.U
    stallCycles := 0.U
    hits        := 0.U
    drainCycles := 0.U
    val code = Mux(
      overflow,
      AccelError.LoadOverflow.U,
      Mux(n > p.capacity.U, AccelError.CountOverCapacity.U, Mux(n > loaded, AccelError.CountOverLoaded.U, AccelError.None.U))
    )
    error := code
    // Runs with errors, and runs with nothing to pair, end at once.
    val runs = code === AccelError.None.U && n >= 2.U
    busy                     := runs
    done                     := !runs
    sequencer.io.start.valid := runs
  }

  // ---- pipeline ----
  // Valid bits of the cycles in flight between issue and the result queue.
  val inFlight = Wire(UInt(log2Ceil(p.pipelineLatency + 1).W))
  sequencer.io.advance := queue.io.count +& inFlight < p.resultQueueDepth.U
  val issue = sequencer.io.issue

  buffer.io.readEnable := busy
  buffer.io.aRow       := issue.bits.aRow
  buffer.io.bRows      := issue.bits.bRows

  class Meta extends Bundle {
    val iBase    = UInt(p.indexWidth.W)
    val jBase    = UInt(p.indexWidth.W)
    val laneMask = UInt(m.W)
    val rotate   = UInt(p.laneWidth.W)
    val probeI   = Vec(m, UInt(p.indexWidth.W))       // only used with the debug port
    val probeJ   = Vec(m, UInt(p.indexWidth.W))
  }
  val issued = Wire(Valid(new Meta))
  issued.valid              := issue.valid
  issued.bits.iBase         := issue.bits.iBase
  issued.bits.jBase         := issue.bits.jBase
  issued.bits.laneMask      := issue.bits.laneMask
  issued.bits.rotate        := issue.bits.rotate
  if (p.debugPort) {
    // The objects each lane really sees: derived from the row addresses given
    // to the memories and the rotator's selection, not from iBase/jBase.
    issued.bits.probeI := VecInit(Seq.tabulate(m)(k => (issue.bits.aRow * m.U + k.U)(p.indexWidth - 1, 0)))
    val portObjects = VecInit(Seq.tabulate(m)(k => (issue.bits.bRows(k) * m.U + k.U)(p.indexWidth - 1, 0)))
    issued.bits.probeJ := Rotator(portObjects, issue.bits.rotate)
  } else {
    issued.bits.probeI := DontCare
    issued.bits.probeJ := DontCare
  }

  private def stage(x: Valid[Meta]): Valid[Meta] = {
    val r = Wire(Valid(new Meta))
    r.valid := RegNext(x.valid, false.B)
    r.bits  := RegNext(x.bits)
    r
  }

  // Memory read (1 cycle) and the memory output registers.
  val atMemory = stage(issued)
  val memoryStages = Seq.iterate((buffer.io.a, buffer.io.b, atMemory), p.memoryOutputStages + 1) {
    case (a, b, meta) => (RegNext(a), RegNext(b), stage(meta))
  }
  val (memA, memB, atBuffered) = memoryStages.last
  // Rotator, registered.
  val rotatedB  = RegNext(Rotator(memB, atBuffered.bits.rotate))
  val alignedA  = RegNext(memA)
  val atRotated = stage(atBuffered)
  // Comparators and AND gates, registered.
  compare.io.a := alignedA
  compare.io.b := rotatedB
  val hitMask   = Reg(UInt(m.W))
  hitMask := compare.io.hits & atRotated.bits.laneMask
  val atCompare = stage(atRotated)

  val stages = memoryStages.map(_._3) ++ Seq(atRotated, atCompare)
  require(stages.length == p.pipelineLatency)
  inFlight := PopCount(stages.map(_.valid))

  queue.io.enq.valid      := atCompare.valid && hitMask.orR
  queue.io.enq.bits.iBase := atCompare.bits.iBase
  queue.io.enq.bits.jBase := atCompare.bits.jBase
  queue.io.enq.bits.mask  := hitMask
  assert(!queue.io.enq.valid || queue.io.enq.ready, "result queue overflow: credit accounting is broken")
  io.result <> queue.io.deq

  // ---- run bookkeeping ----
  when(busy) {
    cycles := cycles + 1.U
    when(issue.valid) {
      issueCycles := issueCycles + 1.U
    }.elsewhen(sequencer.io.active) {
      stallCycles := stallCycles + 1.U
    }.otherwise {
      // Draining: the first runOverheadCycles cycles are the pipeline's
      // fixed latency; any beyond are spent waiting for the consumer.
      when(drainCycles === p.runOverheadCycles.U) {
        stallCycles := stallCycles + 1.U
      }.otherwise {
        drainCycles := drainCycles + 1.U
      }
      when(inFlight === 0.U && queue.io.count === 0.U) {
        busy := false.B
        done := true.B
      }
    }
  }
  // Counted as beats enter the queue, from the registered hit mask: counting at
  // the consumer put the queue's read multiplexer, a popcount and a 64-bit add
  // on one path (the critical one on ECP5). Every queued beat is delivered
  // before done rises, so after a run this equals the pairs handed over.
  when(queue.io.enq.fire) {
    hits := hits + PopCount(hitMask)
  }

  io.status.busy   := busy
  io.status.done   := done
  io.status.error  := error
  io.status.loaded := loaded

  io.info.m                 := p.m.U
  io.info.capacity          := p.capacity.U
  io.info.keyWidth          := p.keyWidth.U
  io.info.runOverheadCycles := p.runOverheadCycles.U

  io.counters.loadCycles  := loadCycles
  io.counters.cycles      := cycles
  io.counters.issueCycles := issueCycles
  io.counters.stallCycles := stallCycles
  io.counters.hits        := hits

  io.debug.foreach { d =>
    d.cycleValid := atCompare.valid
    for (k <- 0 until m) {
      d.lanes(k).valid := atCompare.valid && atCompare.bits.laneMask(k)
      d.lanes(k).i     := atCompare.bits.probeI(k)
      d.lanes(k).j     := atCompare.bits.probeJ(k)
      d.lanes(k).hit   := hitMask(k)
    }
  }
}
