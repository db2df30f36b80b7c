package bpaccel

import chisel3._
import chisel3.util._

/** A group of properties the [[FormalHarness]] asserts; each has its own
  * assertion messages, so a failing check names the group that caught it.
  */
sealed abstract class Property(val name: String)
object Property {
  /** The result queue never holds more than its depth, and hands the consumer
    * exactly the beats that entered it, each once, in order, whatever `ready` does.
    * The beat that enters is the one the lanes define (bases read off them),
    * so this also checks the bases the design reports.
    */
  case object ExactlyOnce extends Property("exactly-once")
  /** `done` means every beat was taken and none will come; it stays until the next start. */
  case object Done extends Property("done")
  /** A start with an error (or fewer than two objects) ends at once with its code and no beat. */
  case object ErrorStart extends Property("error-start")
  /** Each lane compares i < j < n (a bipartite run: i < na <= j), and the beats of a run are distinct pairs
    * (lane k of a beat on ((iBase + k) mod 2^indexWidth, (jBase + k) mod 2^indexWidth)).
    */
  case object Lanes extends Property("lanes")
  /** A run tests n(n-1)/2 pairs, a bipartite one na(n-na) (with [[Lanes]]: all of them), and each hit bit is the overlap of boxes i and j. */
  case object Pairs extends Property("pairs")

  val all: Seq[Property] = Seq(ExactlyOnce, Done, ErrorStart, Lanes, Pairs)
}

/** Formal-only wrapper: the accelerator with every input free (boxes, start
  * counts, load/start/ready timing) and monitors that assert `properties`.
  * The monitors see only the top level's ports, with the debug port's
  * per-lane view of what the comparators hold (tags that travelled with the
  * boxes); they keep their own model of what was loaded and what entered the
  * result queue, independent of the design's registers.
  */
class FormalHarness(p: AccelParams, properties: Set[Property] = Property.all.toSet) extends Module {
  require(p.debugPort, "the formal checks watch the lanes through the debug port")
  val io = IO(new Bundle {
    val load   = Flipped(Decoupled(new Aabb(p.keyWidth)))
    val start  = Flipped(Decoupled(new RunRequest(p)))
    val cells  = Flipped(Decoupled(new RunRequest(p)))
    val result = Decoupled(new ResultBeat(p))
  })
  private val m     = p.m
  private val depth = p.resultQueueDepth

  val dut = Module(new BroadPhaseAccel(p))
  dut.io.load <> io.load
  dut.io.start <> io.start // any split: triangular runs (0), bipartite ones, and bad splits
  // Single runs only: batches are checked in simulation (BatchSpec). An
  // assumption rather than a constant, which firrtl2's constant propagation
  // cannot fold through the batch front end (it fails with an internal error).
  dut.io.cells <> io.cells
  assume(!io.cells.valid, "the formal checks cover single runs: no batch")
  io.result <> dut.io.result
  private val status = dut.io.status
  private val lanes  = dut.io.debug.get.lanes
  private val cycle  = dut.io.debug.get.cycleValid // a schedule cycle leaves the AND stage

  private def check(property: Property, cond: Bool, what: String): Unit =
    if (properties.contains(property)) assert(cond, s"[${property.name}] $what")

  // ---- what the consumer has asked for: loads and starts ----
  // Boxes of the run being loaded, numbered as the protocol says: from 0 after each start.
  val loaded = RegInit(0.U(log2Ceil(p.capacity + 2).W)) // saturates at capacity + 1: overflow
  val boxes  = Reg(Vec(p.capacity, new Aabb(p.keyWidth)))
  when(io.load.fire) {
    when(loaded < p.capacity.U) { boxes(loaded(p.indexWidth - 1, 0)) := io.load.bits }
    when(loaded <= p.capacity.U) { loaded := loaded + 1.U }
  }
  val n         = Reg(UInt(p.countWidth.W))
  val na        = Reg(UInt(p.countWidth.W)) // the run's split: 0, or the A objects of a bipartite run
  val goodRun   = RegInit(false.B) // the last start launched a run of n >= 2 objects
  val quietRun  = RegInit(false.B) // the last start had an error or n < 2: nothing may be compared
  val startCode = Wire(AccelError())
  startCode := MuxCase(
    AccelError.None,
    Seq(
      (loaded > p.capacity.U)      -> AccelError.LoadOverflow,
      (io.start.bits.count > p.capacity.U) -> AccelError.CountOverCapacity,
      (io.start.bits.count > loaded)     -> AccelError.CountOverLoaded,
      (io.start.bits.split =/= 0.U && !p.bipartiteRuns.B) -> AccelError.SplitUnsupported,
      (io.start.bits.split =/= 0.U && io.start.bits.split >= io.start.bits.count) -> AccelError.SplitOutOfRange
    )
  )
  val startedQuiet = RegNext(io.start.fire && (startCode =/= AccelError.None || io.start.bits.count < 2.U), false.B)
  val quietCode    = RegNext(startCode)
  when(io.start.fire) {
    loaded   := 0.U
    n        := io.start.bits.count
    na       := io.start.bits.split
    goodRun  := startCode === AccelError.None && io.start.bits.count >= 2.U
    quietRun := !(startCode === AccelError.None && io.start.bits.count >= 2.U)
  }

  // ---- the cycle's beat: (iBase, jBase) with lane k on (iBase + k, jBase + k), modulo 2^indexWidth ----
  // Read off the lowest lane that compares: in a bipartite run lane 0 may
  // not, and after the reader's jump it holds an object of A that does not
  // follow the window's later lanes (the beat names the objects compared);
  // in a stream run of fewer than m + 2 objects the lanes below the head
  // pad do not either, and the bases wrap below 0 (l.i - k wraps in UInt).
  val anyValid = lanes.map(_.valid).reduce(_ || _)
  val iBase    = PriorityMux(lanes.map(_.valid), lanes.zipWithIndex.map { case (l, k) => l.i - k.U })
  val jBase    = PriorityMux(lanes.map(_.valid), lanes.zipWithIndex.map { case (l, k) => l.j - k.U })

  // ---- a model of the result queue: the beats that entered it and were not yet taken ----
  val hitMask  = VecInit(lanes.map(_.hit)).asUInt
  val entering = Wire(new ResultBeat(p))
  entering.iBase := iBase
  entering.jBase := jBase
  entering.mask  := hitMask
  entering.cell  := 0.U
  val enters  = cycle && hitMask.orR
  val slots   = depth + 1 // one more than the queue, so the model itself never overflows
  val held    = Reg(Vec(slots, new ResultBeat(p)))
  val head    = RegInit(0.U(log2Ceil(slots).W))
  val tail    = RegInit(0.U(log2Ceil(slots).W))
  val count   = RegInit(0.U(log2Ceil(slots + 1).W))
  private def wrap(x: UInt): UInt = Mux(x === (slots - 1).U, 0.U, x + 1.U)
  when(enters) { held(tail) := entering; tail := wrap(tail) }
  when(io.result.fire) { head := wrap(head) }
  count := count + enters.asUInt - io.result.fire.asUInt

  check(Property.ExactlyOnce, count <= depth.U, "the result queue holds more beats than its depth")
  check(Property.ExactlyOnce, io.result.valid === (count =/= 0.U || enters),
    "result.valid differs from 'a beat entered and was not taken'")
  check(Property.ExactlyOnce, !io.result.valid || io.result.bits.asUInt === Mux(count === 0.U, entering, held(head)).asUInt,
    "the beat offered is not the oldest one not yet taken")

  // ---- done ----
  check(Property.Done, !status.done || (!status.busy && count === 0.U && !io.result.valid && !cycle),
    "done while a beat is queued, offered or still in the pipeline")
  val wasDone = RegNext(status.done, false.B)
  val started = RegNext(io.start.fire, false.B)
  check(Property.Done, !wasDone || started || status.done, "done fell without a start")

  // ---- error starts ----
  check(Property.ErrorStart, !(quietRun || startedQuiet) || (!cycle && !io.result.valid),
    "a start with an error or fewer than two objects produced a beat")
  check(Property.ErrorStart, !startedQuiet || (status.done && !status.busy && status.error === quietCode),
    "a start with an error or fewer than two objects did not end at once with its code")

  // ---- lanes: i < j < n (bipartite: i < na <= j), and the run's pairs are distinct ----
  for (k <- 0 until m) {
    val lane = lanes(k)
    check(Property.Lanes, !lane.valid || cycle, "a lane is valid outside a schedule cycle")
    check(Property.Lanes, !(cycle && lane.hit) || lane.valid, "a lane hits without a comparison")
    check(Property.Lanes, !lane.valid || (lane.i < lane.j && lane.j < n), "a lane compares i >= j or j >= n")
    check(Property.Lanes, !lane.valid || na === 0.U || (lane.i < na && na <= lane.j),
      "a lane of a bipartite run compares a pair not across its split")
    check(Property.Lanes, !lane.valid || (lane.i === iBase + k.U && lane.j === jBase + k.U),
      "lane k does not hold objects iBase + k and jBase + k")
  }
  check(Property.Lanes, !cycle || goodRun, "a schedule cycle outside a run")
  // A triangular run compares in every cycle, from lane 0 when it has
  // m + 2 objects or more; a shorter run's objects may start up the lanes.
  val longRun = n >= (m + 2).U // more than one block is possible
  check(Property.Lanes, !cycle || na =/= 0.U || Mux(longRun, lanes(0).valid, anyValid),
    "a schedule cycle of a triangular run without lane 0 (n >= m + 2) or without any lane")
  // No pair is tested twice: pair (i, j) of lane k names its beat and lane.
  //  - A run of n >= m + 2 objects: iBase a multiple of m and i = iBase + k
  //    without wrapping, so i names iBase and k.
  //  - A shorter run has one block: every beat has the run's first iBase,
  //    so i names k ((i - iBase) mod 2^w).
  //  - Beats rise strictly in (iBase, (jBase - iBase) mod 2^w), and j - i is
  //    that difference, so within one iBase it names the beat.
  val compares = cycle && anyValid
  val delta    = jBase - iBase // j - i of every lane, modulo 2^indexWidth
  check(Property.Lanes, !(compares && longRun) || iBase % m.U === 0.U, "iBase is not a multiple of m")
  for (lane <- lanes)
    check(Property.Lanes, !(lane.valid && longRun) || lane.i >= iBase, "a lane's i wraps below iBase in a long run")
  val seen  = RegInit(false.B)
  val lastI = Reg(UInt(p.indexWidth.W))
  val lastD = Reg(UInt(p.indexWidth.W))
  check(Property.Lanes, !(compares && seen && !longRun) || iBase === lastI,
    "a run of fewer than m + 2 objects changes iBase: it has one block")
  check(Property.Lanes,
    !(compares && seen) || iBase > lastI || (iBase === lastI && delta > lastD),
    "a beat's (iBase, jBase - iBase) does not follow the previous one's: a pair may repeat")
  when(compares) { seen := true.B; lastI := iBase; lastD := delta }
  when(io.start.fire) { seen := false.B }

  // ---- pairs: all n(n-1)/2 tested (bipartite: na(n-na)), each hit bit right ----
  val pairWidth = log2Ceil(p.capacity * (p.capacity - 1) / 2 + 1) + 1
  val tested    = RegInit(0.U(pairWidth.W))
  when(cycle) { tested := tested + PopCount(lanes.map(_.valid)) }
  when(io.start.fire) { tested := 0.U }
  val allPairs = Mux(na === 0.U, (n * (n - 1.U)) >> 1, na * (n - na))
  check(Property.Pairs, !(status.done && goodRun) || tested === allPairs,
    "a run ended without testing n(n-1)/2 pairs, or na(n-na) across a split")
  private def overlap(x: Aabb, y: Aabb): Bool =
    (0 until 3).map(a => x.min(a) <= y.max(a) && y.min(a) <= x.max(a)).reduce(_ && _)
  for (lane <- lanes) {
    check(Property.Pairs, !(lane.valid && lane.j < p.capacity.U) || lane.hit === overlap(boxes(lane.i), boxes(lane.j)),
      "a hit bit is not the overlap of the loaded boxes i and j")
  }
}
