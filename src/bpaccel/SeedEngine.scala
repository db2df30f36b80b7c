package bpaccel

import chisel3._
import chisel3.util._

/** The seed's architecture: striped coordinate buffers, the A/B address
  * sequencer, the rotator and the comparator array.
  *
  * Pipeline, one schedule cycle per clock when unstalled:
  * issue -> memory read -> memory output registers -> rotator register ->
  * comparator/AND register. The sequencer only issues when the top level
  * grants a credit (`advance`), so the pipeline itself never stalls.
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
  sequencer.io.advance := io.advance
  val issue = sequencer.io.issue

  buffer.io.readEnable := sequencer.io.active
  buffer.io.aRow       := issue.bits.aRow
  buffer.io.bRows      := issue.bits.bRows

  class Meta extends Bundle {
    val iBase    = UInt(p.indexWidth.W)
    val jBase    = UInt(p.indexWidth.W)
    val laneMask = UInt(m.W)
    val rotate   = UInt(p.laneWidth.W)
    val probeI   = Vec(m, UInt(p.indexWidth.W)) // only used with the debug port
    val probeJ   = Vec(m, UInt(p.indexWidth.W))
  }
  val meta = Wire(new Meta)
  meta.iBase    := issue.bits.iBase
  meta.jBase    := issue.bits.jBase
  meta.laneMask := issue.bits.laneMask
  meta.rotate   := issue.bits.rotate
  if (p.debugPort) {
    // The objects each lane really sees: derived from the row addresses given
    // to the memories and the rotator's selection, not from iBase/jBase.
    meta.probeI := VecInit(Seq.tabulate(m)(k => (issue.bits.aRow * m.U + k.U)(p.indexWidth - 1, 0)))
    val portObjects = VecInit(Seq.tabulate(m)(k => (issue.bits.bRows(k) * m.U + k.U)(p.indexWidth - 1, 0)))
    meta.probeJ := Rotator(portObjects, issue.bits.rotate)
  } else {
    meta.probeI := DontCare
    meta.probeJ := DontCare
  }

  // Memory read (1 cycle), then the memory output registers.
  val atMemory = Pipe(issue.valid, meta)
  val memoryStages = Seq.iterate((buffer.io.a, buffer.io.b, atMemory), p.memoryOutputStages + 1) {
    case (a, b, at) => (RegNext(a), RegNext(b), Pipe(at))
  }
  val (memA, memB, atBuffered) = memoryStages.last
  // Rotator, registered.
  val rotatedB  = RegNext(Rotator(memB, atBuffered.bits.rotate))
  val alignedA  = RegNext(memA)
  val atRotated = Pipe(atBuffered)
  // Comparators and AND gates, registered.
  compare.io.a := alignedA
  compare.io.b := rotatedB
  val hitMask   = RegNext(compare.io.hits & atRotated.bits.laneMask)
  val atCompare = Pipe(atRotated)

  val stages = memoryStages.map(_._3) ++ Seq(atRotated, atCompare)
  require(stages.length == p.pipelineLatency)

  io.activity.active   := sequencer.io.active
  io.activity.issued   := issue.valid
  io.activity.stalled  := sequencer.io.active && !issue.valid
  io.activity.inFlight := PopCount(stages.map(_.valid))

  emit(atCompare.valid, atCompare.bits.iBase, atCompare.bits.jBase, atCompare.bits.laneMask, atCompare.bits.probeI, atCompare.bits.probeJ, hitMask)
}
