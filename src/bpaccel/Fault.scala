package bpaccel

/** Deliberate design faults, one bug each, for the mutant tests of the formal
  * checks (test/bpaccel/FormalSpec.scala) and of batches (BatchSpec): each
  * check must fail on the fault it is meant to catch, so a passing proof is not vacuous. Only
  * [[AccelParams.faults]] turns one on; the default (no fault) elaborates to
  * exactly the design without them.
  */
sealed abstract class Fault(val description: String)

object Fault {
  /** The credit check believes the result queue has one more entry than it has. */
  case object CreditOneTooMany extends Fault("credit check counts one result-queue entry too many")
  /** The result queue lets a beat go when the consumer is not ready: it is lost. */
  case object DropBeatWhenNotReady extends Fault("result queue dequeues while the consumer is not ready")
  /** A run ends once the engine is idle, without waiting for the queued beats. */
  case object DoneBeforeQueueEmpty extends Fault("done rises before the result queue is empty")
  /** Loading a box after a run clears `done` although no run started. */
  case object DoneClearedByLoad extends Fault("a load after a run clears done")
  /** A start with an error still launches the engine. */
  case object ErrorStartLaunches extends Fault("a start with an error launches the engine")
  /** Lane k is compared while k more objects remain instead of more than k: its partner is object n. */
  case object LaneMaskOneTooWide extends Fault("lane mask lets a lane compare one object past the last")
  /** The AND stage sends its last beat again in the cycle after it. */
  case object RepeatLastBeat extends Fault("the last beat before a gap is sent twice")
  /** A run of m+2 objects skips its second block: its pairs are never tested. */
  case object SkipSecondBlockAtMPlus2 extends Fault("a run of m+2 objects skips its second block")
  /** The comparators test min < max instead of min <= max: touching boxes are missed. */
  case object StrictCompare extends Fault("comparators miss touching boxes")
  /** The stream's start copies objects 0 .. m-1 into the window instead of 1 .. m: lane k meets itself. */
  case object HeadCopyOffByOne extends Fault("the stream's start copies the head registers into the window one lane off")
  /** The stream's window enables, computed a cycle ahead, ignore the result queue's back-pressure. */
  case object LookaheadIgnoresRoom extends Fault("the stream's look-ahead window enables ignore back-pressure")
  /** A bipartite stream run does not mask the A lanes past the last A object: they test pairs inside B. */
  case object BipartiteALanesUnmasked extends Fault("a bipartite run's lanes past the last A object are not masked")
  /** The batch front end does not count cells of fewer than two objects: later cells get the wrong tag. */
  case object CellCounterSkipsShortCells extends Fault("the batch's cell counter skips cells of 0 or 1 objects")
  /** The batch front end takes the next count only when a cell ends, as before loads overlapped runs. */
  case object BatchLoadsInSeries extends Fault("the batch loads its next cell only after the last one ended")
  /** The stream's window and A block miss the head registers' copy in the cycle after a start, so a batch's next cell may write them first. */
  case object HeadCopiedLate extends Fault("the stream's window misses the head registers' copy in the cycle after a start")
  /** A short stream run's beat bases are not moved down by the lanes its objects start up the head chain. */
  case object ShortRunBasesNotMoved extends Fault("a short stream run's beat bases are not moved down by the head pad")

  val all: Seq[Fault] = Seq(
    CreditOneTooMany,
    DropBeatWhenNotReady,
    DoneBeforeQueueEmpty,
    DoneClearedByLoad,
    ErrorStartLaunches,
    LaneMaskOneTooWide,
    BipartiteALanesUnmasked,
    RepeatLastBeat,
    SkipSecondBlockAtMPlus2,
    StrictCompare,
    HeadCopyOffByOne,
    LookaheadIgnoresRoom,
    CellCounterSkipsShortCells,
    BatchLoadsInSeries,
    HeadCopiedLate,
    ShortRunBasesNotMoved
  )
}
