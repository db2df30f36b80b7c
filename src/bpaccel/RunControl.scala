package bpaccel

import chisel3._
import chisel3.util._

/** What an engine tells run control each cycle. */
class EngineActivity(p: AccelParams) extends Bundle {
  val active   = Bool() // the schedule is not finished (starting up or issuing)
  val issued   = Bool() // a schedule cycle was issued
  val stalled  = Bool() // a schedule cycle was ready but the result queue had no room
  val inFlight = UInt(log2Ceil(p.pipelineLatency + 1).W) // issued cycles not yet at the result queue
  val retired  = Bool() // an issued cycle leaves the pipeline (the last stage is valid)
}

/** Starts runs, decodes their errors, ends them, and keeps the counters.
  *
  * A start is checked against what was loaded: an error, or fewer than two
  * objects, ends the run at once with no results. Otherwise the engine is
  * launched and the run ends once the engine is done, nothing is in flight
  * and every queued beat was taken.
  *
  * In a batch ([[BatchControl]]) the starts of its later cells `accumulate`:
  * the counters add up over the batch and the first error of the batch
  * stays, and each `frontEndCycle` counts as device time. Loads may overlap
  * runs there, so a batch counts its cycles once each: `cycles` those of its
  * runs and its front end, `loadCycles` every other one from the `begin` on
  * (loading that no run hides, and the starts). Their sum is the batch's
  * time on the device.
  */
class RunControl(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val start      = Flipped(Decoupled(new RunRequest(p)))
    val accumulate = Input(Bool()) // this start continues a batch
    val batchBegin = Input(Bool()) // a batch's first count is accepted: its load time starts
    val batchActive = Input(Bool()) // a batch is under way
    val frontEndCycle = Input(Bool()) // a cycle the batch front end spends between cells
    val loadFire   = Input(Bool())
    val loaded     = Input(UInt(p.countWidth.W))
    val overflow   = Input(Bool())
    val launch     = Valid(UInt(p.countWidth.W)) // n >= 2, no error
    val engine     = Input(new EngineActivity(p))
    val queuedHits = Flipped(Valid(UInt(log2Ceil(p.m + 1).W))) // pairs entering the result queue
    val queueEmpty = Input(Bool())
    val status     = Output(new RunStatus(p))
    val counters   = Output(new AccelCounters(p))
  })

  val busy  = RegInit(false.B)
  val done  = RegInit(false.B)
  val error = RegInit(AccelError.None)

  private def counter() = RegInit(0.U(p.counterWidth.W))
  val cycles      = counter()
  val issueCycles = counter()
  val stallCycles = counter()
  val hits        = counter()
  val loadCycles  = counter()
  // Load cycles of the run being loaded: from its first accepted box to the
  // cycle that accepts its start, pauses included, since the device belongs
  // to that run from its first box on. Published in loadCycles at the start.
  // Kept as the value a start in this cycle would publish (the start cycle
  // included), so that the start adds one register to the counter, not two
  // 64-bit adds in series.
  val loading          = RegInit(false.B)
  val loadCyclesAtStart = RegInit(1.U(p.counterWidth.W))
  val drainCycles   = RegInit(0.U(log2Ceil(p.runOverheadCycles + 1).W))

  io.start.ready := !busy

  when(io.loadFire && !loading) {
    loading           := true.B
    loadCyclesAtStart := 2.U // this cycle and a start in the next
  }.elsewhen(loading) {
    loadCyclesAtStart := loadCyclesAtStart + 1.U
  }

  io.launch.valid := false.B
  io.launch.bits  := io.start.bits.count
  when(io.start.fire) {
    val n     = io.start.bits.count
    val split = io.start.bits.split
    val code = MuxCase(
      AccelError.None,
      Seq(
        io.overflow            -> AccelError.LoadOverflow,
        (n > p.capacity.U)     -> AccelError.CountOverCapacity,
        (n > io.loaded)        -> AccelError.CountOverLoaded,
        (split =/= 0.U && !p.bipartiteRuns.B) -> AccelError.SplitUnsupported,
        (split =/= 0.U && split >= n) -> AccelError.SplitOutOfRange
      )
    )
    error := Mux(io.accumulate && error =/= AccelError.None, error, code)
    val runs = (if (p.has(Fault.ErrorStartLaunches)) true.B else code === AccelError.None) && n >= 2.U
    busy            := runs
    done            := !runs
    io.launch.valid := runs
    when(!io.batchActive) { loadCycles := loadCyclesAtStart }
    loading           := false.B
    loadCyclesAtStart := 1.U // a start with nothing loaded costs its own cycle
    drainCycles     := 0.U
    when(!io.accumulate) {
      cycles      := 0.U
      issueCycles := 0.U
      stallCycles := 0.U
      hits        := 0.U
    }
  }
  when(io.frontEndCycle) { cycles := cycles + 1.U } // never while busy
  // A batch's load time: one add a cycle, not the single run's span added at
  // the start (two 64-bit adds in series were seed m = 8's critical path).
  when(io.batchBegin) {
    loadCycles := 1.U
  }.elsewhen(io.batchActive && !busy && !io.frontEndCycle) {
    loadCycles := loadCycles + 1.U
  }

  // The issue and stall counts take the engine's flags a cycle late, from
  // registers of their own, so that `issue` does not drive these 128
  // flip-flops and pull its LUT away from the engine's control. The last
  // issue or stall of a run comes at least
  // pipelineLatency cycles before its done, so its count lands while busy.
  val issuedLate  = RegNext(io.engine.issued, false.B)
  val stalledLate = RegNext(io.engine.stalled, false.B)
  assert(busy || !(issuedLate || stalledLate), "an issue or stall was counted after its run ended")
  when(busy) {
    cycles := cycles + 1.U
    when(issuedLate) { issueCycles := issueCycles + 1.U }
    // Draining: the first runOverheadCycles cycles are the pipeline's fixed
    // latency; any beyond are spent waiting for the consumer. A drain
    // follows the last issue or stall by a cycle at least, so the two
    // stall counts never meet.
    val drainStall = !io.engine.active && drainCycles === p.runOverheadCycles.U
    when(stalledLate || drainStall) { stallCycles := stallCycles + 1.U }
    when(!io.engine.active) {
      when(drainCycles =/= p.runOverheadCycles.U) { drainCycles := drainCycles + 1.U }
      val drained = if (p.has(Fault.DoneBeforeQueueEmpty)) true.B else io.queueEmpty
      when(io.engine.inFlight === 0.U && drained) {
        busy := false.B
        done := true.B
      }
    }
  }
  // Counted as beats enter the queue, from a registered hit mask: counting at
  // the consumer put the queue's read multiplexer, a popcount and a 64-bit add
  // on one path. Every queued beat is delivered before done rises.
  when(io.queuedHits.valid) { hits := hits + io.queuedHits.bits }
  if (p.has(Fault.DoneClearedByLoad)) when(io.loadFire) { done := false.B }

  io.status.busy  := busy
  // A box beyond the capacity shows at once; the next start fails with it.
  io.status.error  := Mux(io.overflow, AccelError.LoadOverflow, error)
  io.status.done   := done
  io.status.loaded := io.loaded

  io.counters.loadCycles  := loadCycles
  io.counters.cycles      := cycles
  io.counters.issueCycles := issueCycles
  io.counters.stallCycles := stallCycles
  io.counters.hits        := hits
}
