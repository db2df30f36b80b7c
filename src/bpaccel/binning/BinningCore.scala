package bpaccel.binning

import chisel3._
import chisel3.util._

/** The binning device's core (docs/binning.md): takes a FRAME's header and
  * boxes from the stream shell, bins the boxes into the cells of a uniform
  * grid in its groups' memories, runs every cell's all-pairs test on its lane
  * group, and returns each overlapping pair exactly once, then the frame's
  * summary. `abort` returns it to idle at once (its tables are then cleared,
  * localCells cycles, before it takes the next header); nothing more is sent.
  */
class BinningCore(val p: BinningParams) extends Module {
  val io = IO(new BinningPorts(p) {
    val debug = if (p.debugPort) Some(Output(Vec(p.groups, new GroupProbe(p)))) else None
  })
  // An abort resets every register of the core (the memories keep their
  // contents; the cleared tables are all that the next frame relies on).
  private val softReset = reset.asBool || io.abort
  val control = withReset(softReset)(Module(new FrameControl(p)))
  val intake  = withReset(softReset)(Module(new Intake(p)))
  val groups  = Seq.fill(p.groups)(withReset(softReset)(Module(new LaneGroup(p))))
  val merge   = withReset(softReset)(Module(new PairMerge(p)))

  /** Connects a port through, but takes and offers nothing in a cycle of abort. */
  private def unlessAborted[T <: Data](from: DecoupledIO[T], to: DecoupledIO[T]): Unit = {
    to.valid   := from.valid && !io.abort
    to.bits    := from.bits
    from.ready := to.ready && !io.abort
  }
  unlessAborted(io.frame, control.io.frame)
  unlessAborted(io.boxes, intake.io.boxes)
  unlessAborted(merge.io.out, io.pairs)
  unlessAborted(control.io.summary, io.summary)

  intake.io.frameStart  := control.io.frameStart
  intake.io.headerError := control.io.headerError
  intake.io.active      := control.io.intakeActive
  intake.io.n     := control.io.n
  intake.io.shift := control.io.shift
  intake.io.dims  := control.io.dims
  control.io.intakeError   := intake.io.error
  control.io.lastTaken     := intake.io.lastTaken
  control.io.intakeHolding := intake.io.holding
  control.io.received      := intake.io.received

  for ((g, k) <- groups.zipWithIndex) {
    g.io.in <> intake.io.groups(k)
    g.io.frameStart := control.io.frameStart
    g.io.start      := control.io.startGroups
    g.io.clear      := control.io.clear
    g.io.localDims  := control.io.localDims
    merge.io.groups(k) <> g.io.out
  }
  merge.io.restart := control.io.frameStart
  control.io.groupsIdle  := groups.map(_.io.intakeIdle).reduce(_ && _)
  control.io.groupsDone  := groups.map(_.io.done).reduce(_ && _)
  control.io.outputEmpty := groups.map(_.io.empty).reduce(_ && _) && merge.io.empty
  // Sums and the maximum over the groups, as balanced trees at the groups'
  // own widths (sums widen a bit a level) cut into two registered halves of
  // their depth. Two cycles late is still in time for the summary: a group's
  // entry count stops at least two cycles before the intake ends, which is
  // at least localCells cycles before the summary; its issue count stops
  // three cycles before the group is done (compare, AND, then idle).
  private def twoStages(xs: Seq[UInt])(op: (UInt, UInt) => UInt): UInt = {
    def registered(x: UInt): UInt = { val r = Reg(chiselTypeOf(x)); r := x; r } // keeps the width (RegNext drops it)
    val chunk = 1 << ((log2Ceil(xs.length) + 1) / 2)
    registered(VecInit(xs.grouped(chunk).map(c => registered(VecInit(c).reduceTree(op))).toSeq).reduceTree(op))
  }
  control.io.entries    := twoStages(groups.map(_.io.entries))(_ +& _).pad(32)
  control.io.maxEntries := twoStages(groups.map(_.io.entries))((a, b) => Mux(a > b, a, b)).pad(32)
  private val issueSum = twoStages(groups.map(_.io.issues))(_ +& _)
  control.io.issueCycles := issueSum(issueSum.getWidth.min(p.counterWidth) - 1, 0).pad(p.counterWidth)

  control.io.pairsOffered := io.pairs.valid
  control.io.pairsTaken   := Mux(io.pairs.fire, PopCount(io.pairs.bits.pairs.map(_.valid)), 0.U)


  io.debug.foreach(d => for ((g, k) <- groups.zipWithIndex) d(k) := g.io.probe)
}
