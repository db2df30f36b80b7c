package bpaccel

import chisel3._
import chisel3.experimental.BundleLiterals._
import chisel3.util._

/** One axis-aligned bounding box as six order-preserving keys. */
class Aabb(keyWidth: Int) extends Bundle {
  val min = Vec(3, UInt(keyWidth.W))
  val max = Vec(3, UInt(keyWidth.W))
}

/** What an engine produces each issued schedule cycle: all its hits.
  * Lane k set in `mask` means objects (iBase + k) and (jBase + k) overlap,
  * both sums taken modulo 2^indexWidth, with iBase + k < jBase + k always.
  * The modulo matters for the stream's short runs, whose objects start d
  * lanes up: their bases are moved down by d and may wrap, so that the mask
  * leaves unshifted; lanes below d never hit, so no set bit's index wraps.
  */
class ScheduleBeat(p: AccelParams) extends Bundle {
  val iBase = UInt(p.indexWidth.W)
  val jBase = UInt(p.indexWidth.W)
  val mask  = UInt(p.m.W)
}

/** One result beat: a schedule cycle with at least one hit, and the cell of
  * its batch it belongs to (index within the batch from 0, modulo
  * 2^cellTagWidth; 0 for a single run). Indices are local to that cell,
  * and decoded modulo 2^indexWidth as in [[ScheduleBeat]].
  */
class ResultBeat(p: AccelParams) extends ScheduleBeat(p) {
  val cell = UInt(p.cellTagWidth.W)
}

/** What a start or a batch cell asks for: a run of `count` objects, all
  * pairs (`split` = 0), or a bipartite run (`split` = na in 1 .. count-1:
  * only objects 0 .. na-1 against na .. count-1; stream architecture only).
  */
class RunRequest(p: AccelParams) extends Bundle {
  val count = UInt(p.countWidth.W)
  val split = UInt(p.countWidth.W)
}

/** Error codes of a run, also written into the C header. */
object AccelError extends ChiselEnum {
  val None              = Value(0.U) // the run is fine
  val CountOverCapacity = Value(1.U) // start(n) with n > capacity
  val CountOverLoaded   = Value(2.U) // start(n) with fewer than n boxes loaded
  val LoadOverflow      = Value(3.U) // more than capacity boxes were loaded
  val SplitOutOfRange   = Value(4.U) // a split other than 0 outside 1 .. n-1
  val SplitUnsupported  = Value(5.U) // a split on an architecture without bipartite runs (the seed)
  val names: Seq[(String, Type)] = Seq(
    "NONE" -> None,
    "COUNT_OVER_CAPACITY" -> CountOverCapacity,
    "COUNT_OVER_LOADED" -> CountOverLoaded,
    "LOAD_OVERFLOW" -> LoadOverflow,
    "SPLIT_OUT_OF_RANGE" -> SplitOutOfRange,
    "SPLIT_UNSUPPORTED" -> SplitUnsupported
  )
  def code(e: Type): Int = e.litValue.toInt
}

/** What run control knows: its run, or the batch it runs. */
class RunStatus(p: AccelParams) extends Bundle {
  val busy   = Bool() // a run or a batch is under way
  val done   = Bool() // the last run or batch ended (with or without error) and nothing started since
  val error  = AccelError() // in a batch: the first error of any of its cells
  val loaded = UInt(p.countWidth.W)
}

class AccelStatus(p: AccelParams) extends RunStatus(p) {
  val batch     = Bool()     // a batch is under way: cells are queued or running
  val cellsDone = UInt(32.W) // cells of the current or last batch that have ended
}

/** Of the last run, or summed over the cells of the last batch (see docs/microarchitecture.md). */
class AccelCounters(p: AccelParams) extends Bundle {
  val loadCycles  = UInt(p.counterWidth.W) // first box loaded .. start accepted, both included (1 if no box);
                                           // in a batch: its cycles outside runs and cell ends
  val cycles      = UInt(p.counterWidth.W) // start accepted .. done
  val issueCycles = UInt(p.counterWidth.W) // cycles the comparator array was given work
  val stallCycles = UInt(p.counterWidth.W) // cycles the schedule waited on the result queue
  val hits        = UInt(p.counterWidth.W) // pairs reported (all handed to the consumer by done)
}

/** What one lane tested in one schedule cycle, seen at the comparator output. */
class LaneProbe(p: AccelParams) extends Bundle {
  val valid = Bool()
  val i     = UInt(p.indexWidth.W)
  val j     = UInt(p.indexWidth.W)
  val hit   = Bool()
}

class DebugProbe(p: AccelParams) extends Bundle {
  val cycleValid = Bool() // this cycle carries a scheduled comparison
  val lanes      = Vec(p.m, new LaneProbe(p))
}

/** The configuration as constant outputs, so a host can check that the model
  * it drives is the one its header describes.
  */
class AccelInfo extends Bundle {
  val arch              = UInt(8.W) // Arch.id: 0 seed, 1 stream
  val m                 = UInt(16.W)
  val capacity          = UInt(32.W)
  val keyWidth          = UInt(8.W)
  val runOverheadCycles = UInt(8.W)
  val readLatency       = UInt(8.W) // stream: startup is readLatency cycles
  val batchCells        = UInt(16.W) // cell counts the batch queue holds
  val cellTagWidth      = UInt(8.W)  // bits of a result beat's cell tag
  val batchOverlapsLoads = Bool()    // a batch loads its next cell while one runs
  val bipartiteRuns     = Bool()     // starts and cells may carry a split (RunRequest)
}

object AccelInfo {
  /** The info port's constants: the parameters the C header carries too. */
  def apply(p: AccelParams): AccelInfo = (new AccelInfo).Lit(
    _.arch               -> p.arch.id.U,
    _.m                  -> p.m.U,
    _.capacity           -> p.capacity.U,
    _.keyWidth           -> p.keyWidth.U,
    _.runOverheadCycles  -> p.runOverheadCycles.U,
    _.readLatency        -> p.startupLatency.U,
    _.batchCells         -> p.batchCells.U,
    _.cellTagWidth       -> p.cellTagWidth.U,
    _.batchOverlapsLoads -> p.overlapsLoads.B,
    _.bipartiteRuns      -> p.bipartiteRuns.B
  )
}

/** The ports every architecture's engine offers the shared top level. */
class EngineIO(p: AccelParams) extends Bundle {
  val write    = Flipped(Valid(new LoadWrite(p)))
  val writeOffered = Input(Bool()) // write.valid, unless this cycle clears the loader (Loader)
  val loadClear    = Input(Bool()) // a start or a batch count restarts the numbering of loaded boxes
  val prepare  = Flipped(Valid(new RunRequest(p))) // a start was accepted (launched or not), with its n and split
  val headPad  = Input(UInt(log2Ceil(p.headObjects + 1).W)) // with a start: the loader's head pad (Loader)
  val launch   = Flipped(Valid(UInt(p.countWidth.W))) // a run of n >= 2 objects, all loaded
  val room     = Input(Bool())                        // the result queue has room for one more issue next cycle
  val activity = Output(new EngineActivity(p))
  val out      = Valid(new ScheduleBeat(p))           // one per issued cycle, mask = hits
  val outHit   = Output(Bool())                       // out.bits.mask =/= 0 (registered beside the mask)
  val outHitCounts = Output(Engine.hitCounts(p.m)) // the mask's popcount by groups of lanes, registered beside it
  val probe    = if (p.debugPort) Some(Output(new DebugProbe(p))) else None
}

/** A cycle's hits as the AND stage registers them (see [[Engine.hitRegisters]]). */
class HitSummary(m: Int) extends Bundle {
  val mask   = UInt(m.W)
  val any    = Bool()
  val counts = Engine.hitCounts(m)
}

object Engine {
  /** The AND stage's registers: each lane's hit, whether any lane hit, and
    * the hits counted by groups of lanes. The OR of the lanes is taken before
    * the register, so that no OR tree sits between the last stage and the
    * result queue's write; the group counts keep half the popcount off the
    * path from the mask to the hit counter (docs/fpga.md). Only for an
    * engine whose compares are registered before the AND.
    */
  def hitRegisters(m: Int, hits: UInt): HitSummary = {
    val summary = Wire(new HitSummary(m))
    summary.mask := hits
    summary.any  := hits.orR
    for ((count, lanes) <- summary.counts.zip(hits.asBools.grouped(HitCountGroup))) count := PopCount(lanes)
    RegNext(summary)
  }

  /** Lanes per partial hit count: an 8-bit popcount is a few LUT4 levels. */
  val HitCountGroup = 8
  private def groupSizes(m: Int): Seq[Int] = (0 until m by HitCountGroup).map(g => (m - g).min(HitCountGroup))

  /** One count per group of lanes, each as wide as its group needs. */
  def hitCounts(m: Int): MixedVec[UInt] = MixedVec(groupSizes(m).map(size => UInt(log2Ceil(size + 1).W)))

  /** The sum of [[hitCounts]], as a balanced tree of adds each as wide as its largest sum. */
  def sumHitCounts(m: Int, counts: MixedVec[UInt]): UInt = {
    def sum(terms: Seq[(UInt, Int)]): (UInt, Int) = terms match {
      case Seq(one) => one
      case _ =>
        val (low, high)         = terms.splitAt(terms.length / 2)
        val ((a, maxA), (b, maxB)) = (sum(low), sum(high))
        val width               = log2Ceil(maxA + maxB + 1)
        (a.pad(width) + b.pad(width), maxA + maxB)
    }
    sum(counts.zip(groupSizes(m)).toSeq)._1
  }
}

/** An architecture's datapath: memories, schedule and comparators. */
abstract class Engine(val p: AccelParams) extends Module {
  val io = IO(new EngineIO(p))

  /** Room for one more issue this cycle. The engine registers it itself so that
    * its next value (`io.room`) is at hand to compute enables a cycle ahead.
    */
  protected val advance = RegNext(io.room, false.B)

  /** Drives the result and the debug probe from the pipeline's last stage.
    *
    * The hit and lane masks go out by lane of the engine, with no logic
    * between the AND stage's registers and the result queue: an engine
    * whose lanes hold the run's objects from a lane d other than 0 (the
    * stream's short runs) gives bases already moved down by d, modulo
    * 2^indexWidth (see [[ScheduleBeat]]), so no shift of the masks by d
    * lanes sits here (docs/fpga.md). Probe lane k is engine lane k, as the
    * mask's bit k is.
    */
  protected def emit(
    valid: Bool,
    iBase: UInt,
    jBase: UInt,
    laneMask: UInt,
    probeI: Vec[UInt],
    probeJ: Vec[UInt],
    hits: HitSummary
  ): Unit = {
    val hitMask = hits.mask
    val lanes   = laneMask
    io.out.valid      := valid
    io.out.bits.iBase := iBase
    io.out.bits.jBase := jBase
    io.out.bits.mask  := hitMask
    io.outHit         := hits.any
    io.outHitCounts   := hits.counts
    assert(!valid || hits.any === hitMask.orR, "the any-hit register does not match the hit mask")
    assert(!valid || hits.counts.reduce(_ +& _) === PopCount(hitMask), "the hit counts do not match the hit mask")
    io.probe.foreach { d =>
      d.cycleValid := valid
      for (k <- 0 until p.m) {
        d.lanes(k).valid := valid && lanes(k)
        d.lanes(k).i     := probeI(k)
        d.lanes(k).j     := probeJ(k)
        d.lanes(k).hit   := hitMask(k)
      }
    }
  }
}
