package bpaccel

import chisel3._
import chisel3.util._

/** The stream engine's m lanes (see [[StreamEngine]]): the head chain, the
  * window, the A blocks (`aNext`, `a`), the comparators and the compare and
  * AND stages. They act [[StreamEngine.LaneLag]] cycles after the control
  * decides: each of the control's wide enables reaches them through a chain
  * of registers ([[copies]]), and every other input through [[toLanes]].
  */
class StreamLanes(p: AccelParams) extends Module {
  private val m = p.m
  val io = IO(new Bundle {
    val loaded = Input(new LoadWrite(p))      // the loaded box (StreamReader), for the head chain
    val entry  = Input(new StreamEntry(p))    // the stream's next object (StreamReader's head register)
    val headShift   = Input(new LaneEnable)
    val headCopy    = Input(new LaneEnable)
    val windowWrite = Input(new LaneEnable)
    val aNextWrite  = Input(new LaneEnable)
    val aLoad       = Input(new LaneEnable)
    val splitLane      = Input(UInt(p.countWidth.W))
    val issue          = Input(Bool())
    val laneHasObjects = Input(UInt(m.W))
    val iBase          = Input(UInt(p.indexWidth.W))
    val jBase          = Input(UInt(p.indexWidth.W))
    /** The AND stage: an issued cycle's bases, lanes, probes and hits. */
    val out      = Valid(new StreamLanes.Beat(p))
    val hits     = Output(new HitSummary(m))
    val inFlight = Output(UInt(log2Ceil(p.pipelineLatency + 1).W)) // issued cycles in the lanes' stages
  })

  /** `x` as the lanes see it: [[StreamEngine.LaneLag]] cycles late. */
  private def toLanes[T <: Data](x: T): T =
    (1 to StreamEngine.LaneLag).foldLeft(x) { (value, _) =>
      val late = Reg(chiselTypeOf(value)) // of the value's own type, its width not left to inference
      late := value
      late
    }

  /** One register per lane (`copies` of them) holding the enable's `now` of
    * LaneLag cycles ago, each driving one lane's clock enables, checked to
    * be so except where `unless` held. The chain from the control's lead
    * register goes through one register per group of
    * [[StreamEngine.LaneGroup]] lanes, so that each cycle holds either the
    * look-ahead's logic or the long wire to a far lane, never both. The
    * copies hold the same value, and synthesis would merge them: the FPGA
    * flow keeps them by name (`<name>_replica<k>`, docs/fpga.md).
    *
    * Only the lead has a reset: a group or lane register may hold anything
    * in the first LaneLag cycles after a one-cycle reset, when no box has
    * been loaded (the first reaches a lane LaneLag + 1 cycles after it is
    * offered), so what it shifts or copies is never compared.
    */
  private def copies(name: String, enable: LaneEnable, copies: Int = m): Seq[Bool] = {
    require(StreamEngine.LaneLag == 2, "the chain below is written for two cycles of lag")
    val groups = Seq.tabulate((copies + StreamEngine.LaneGroup - 1) / StreamEngine.LaneGroup)(g =>
      RegNext(enable.lead).suggestName(s"${name}_replica_group$g"))
    // What each copy is checked against, registered once for all of them.
    val afterReset = ShiftRegisters(reset.asBool, StreamEngine.LaneLag, true.B, true.B)
    val nowLate    = ShiftRegister(enable.now, StreamEngine.LaneLag)
    val excused    = ShiftRegister(enable.unless, StreamEngine.LaneLag) || afterReset.reduce(_ || _)
    Seq.tabulate(copies) { k =>
      val copy = RegNext(groups(k / StreamEngine.LaneGroup)).suggestName(s"${name}_replica$k")
      assert(copy === nowLate || excused, s"the look-ahead of $name is wrong")
      copy
    }
  }

  // ---- objects 0 .. m: a chain of head registers beside the window, entered at the top ----
  // After L head objects, object j sits in lane j + m + 1 - min(L, m + 1).
  // A batch writes its next cell's head here while the current cell runs:
  // the start copied these registers in the cycle after it.
  val headRegs  = Reg(Vec(m + 1, new StreamEntry(p)))
  val headShift = copies("headShift", io.headShift, copies = m + 1)
  val laneBox   = toLanes(io.loaded)
  for (k <- 0 to m) when(headShift(k)) {
    if (k == m) {
      headRegs(k).box := laneBox.box.asUInt
      headRegs(k).inB := DontCare // set by lane at the copy into the window
      headRegs(k).tag := StreamEntry.tag(p, laneBox.index)
    } else headRegs(k) := headRegs(k + 1)
  }
  val headCopy = copies("headCopy", io.headCopy)

  // ---- the window: lane k holds object s+k ----
  val window      = Reg(Vec(m, new StreamEntry(p)))
  val entry       = toLanes(io.entry)
  val windowWrite = copies("windowWrite", io.windowWrite)
  // The window takes objects 1 .. m from the head registers at the copy.
  // Lane k then holds object k+1-d, in B when k+1 >= split + d (`splitLane`, 0 for a triangular run).
  private val copiedToLane = if (p.has(Fault.HeadCopyOffByOne)) 0 else 1
  val laneSplit = toLanes(io.splitLane)
  for (k <- 0 until m) when(windowWrite(k)) {
    when(headCopy(k)) {
      window(k)     := headRegs(k + copiedToLane)
      window(k).inB := (k + 1).U >= laneSplit
    }.otherwise {
      window(k) := (if (k == m - 1) entry else window(k + 1))
    }
  }

  // ---- A blocks ----
  // Block 0's A objects come from the head registers at the copy; later
  // blocks': cycle k of a block finds object base+m+k in the top lane, and
  // the first m issues of a block shift it into aNext's top lane, moving the
  // ones before it down (by lane, so the top lane does not drive all m).
  val a          = Reg(Vec(m, new StreamEntry(p)))
  val aNext      = Reg(Vec(m, new StreamEntry(p)))
  val aNextWrite = copies("aNextWrite", io.aNextWrite)
  for (k <- 0 until m) when(aNextWrite(k)) {
    when(headCopy(k)) {
      aNext(k) := headRegs(k)
    }.otherwise {
      aNext(k) := (if (k == m - 1) window(m - 1) else aNext(k + 1))
    }
  }
  val aLoad = copies("aLoad", io.aLoad)
  for (k <- 0 until m) when(aLoad(k)) { a(k) := aNext(k) }

  // ---- comparators: registered compare, then registered AND ----
  // With a reset: the result queue's credits count these stages in flight.
  val laneIssue   = ShiftRegisters(io.issue, StreamEngine.LaneLag, false.B, true.B)
  val laneObjects = toLanes(io.laneHasObjects)
  val beat = Wire(new StreamLanes.Beat(p))
  beat.iBase    := toLanes(io.iBase)
  beat.jBase    := toLanes(io.jBase)
  beat.laneMask := laneObjects & VecInit(window.map(_.inB)).asUInt
  if (p.debugPort) {
    // The objects each lane really holds, from the tags that travelled with
    // the data, by lane of the engine as the hit mask is.
    beat.probeI := VecInit(a.map(_.tag))
    beat.probeJ := VecInit(window.map(_.tag))
  } else {
    beat.probeI := DontCare
    beat.probeJ := DontCare
  }
  private def boxOf(e: StreamEntry): Aabb = e.box.asTypeOf(new Aabb(p.keyWidth))
  // Six comparator results per lane, registered before the AND.
  val compare = Module(new ComparatorArray(p))
  compare.io.a := VecInit(a.map(boxOf))
  compare.io.b := VecInit(window.map(boxOf))
  val compared  = RegNext(compare.io.compares)
  val atCompare = sampled(laneIssue.last, beat)
  io.hits := Engine.hitRegisters(m, ComparatorArray.hits(compared) & atCompare.bits.laneMask)
  val atAnd = sampled(atCompare.valid, atCompare.bits)
  require(p.pipelineLatency == StreamEngine.LaneLag + 2) // the lanes' lag, compare, AND
  io.out      := atAnd
  io.inFlight := PopCount(laneIssue :+ atCompare.valid :+ atAnd.valid)

  /** `Pipe` without the enable on its bits: they are sampled every cycle,
    * since only a valid stage's are read, so `issue` does not reach the lane
    * mask registers of each stage.
    */
  private def sampled[T <: Data](valid: Bool, bits: T): Valid[T] = {
    val stage = Wire(Valid(chiselTypeOf(bits)))
    stage.valid := RegNext(valid, false.B)
    stage.bits  := RegNext(bits)
    stage
  }
}

object StreamLanes {
  /** An issued cycle as the lanes hold it: its bases, the lanes holding
    * objects of the run (by lane of the engine), and, with the debug port,
    * the objects each lane compares.
    */
  class Beat(p: AccelParams) extends Bundle {
    val iBase    = UInt(p.indexWidth.W)
    val jBase    = UInt(p.indexWidth.W)
    val laneMask = UInt(p.m.W)
    val probeI   = Vec(p.m, UInt(p.indexWidth.W)) // only with the debug port
    val probeJ   = Vec(p.m, UInt(p.indexWidth.W))
  }
}
