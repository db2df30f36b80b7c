package bpaccel.binning

import chisel3._
import chisel3.util._

/** Formal-only wrapper of the output path: every group's hit serializer and
  * the merge, with free hit beats (each group's engine sends one whenever its
  * credits allow, any lanes hit) and a free consumer. Each pair is stamped
  * (i = its group, j = its number within the group), so the monitor, which
  * sees only the beats entering and the beats leaving, can tell:
  *  - `delivery`: every pair leaves exactly once, each group's in order, and
  *    nothing leaves that did not enter; once all is empty, all entered pairs left.
  */
class OutputFormalHarness(p: BinningParams) extends Module {
  require(p.indexWidth >= log2Ceil(p.groups))
  val io = IO(new Bundle {
    val send  = Input(Vec(p.groups, Bool()))        // the group's engine sends a beat
    val hit   = Input(Vec(p.groups, Vec(p.g, Bool()))) // its lanes that hit
    val ready = Input(Bool())
  })
  val serializers = Seq.fill(p.groups)(Module(new HitSerializer(p)))
  val merge = Module(new PairMerge(p))
  merge.io.restart := false.B
  merge.io.out.ready := io.ready
  private val seqBits = p.indexWidth
  val entered   = RegInit(VecInit(Seq.fill(p.groups)(0.U(seqBits.W))))
  val delivered = RegInit(VecInit(Seq.fill(p.groups)(0.U(seqBits.W))))
  val queued    = RegInit(VecInit(Seq.fill(p.groups)(0.U(log2Ceil(p.hitQueueDepth + 1).W))))
  for ((s, gr) <- serializers.zipWithIndex) {
    // The engine's credit rule: a beat only when the queue has room (its own count), with at least one hit.
    val sends = io.send(gr) && io.hit(gr).asUInt.orR && queued(gr) < p.hitQueueDepth.U
    s.io.hits.valid := sends
    s.io.hits.bits.hit := io.hit(gr)
    for (k <- 0 until p.g) {
      s.io.hits.bits.pairs(k).i := gr.U
      s.io.hits.bits.pairs(k).j := entered(gr) + PopCount(io.hit(gr).take(k))
    }
    when(sends) { entered(gr) := entered(gr) + PopCount(io.hit(gr)) }
    queued(gr) := queued(gr) + sends.asUInt - s.io.freed.asUInt
    merge.io.groups(gr) <> s.io.out
    assume(entered(gr) < ((1 << seqBits) - p.g).U, "the stamps do not wrap")
  }
  val out = merge.io.out
  for (lane <- out.bits.pairs; gr <- 0 until p.groups) {
    val takes = out.fire && lane.valid && lane.bits.i === gr.U
    assert(!takes || lane.bits.j === delivered(gr), s"[${BinProperty.Delivery.name}] a pair of group $gr left out of order, twice or not at all")
    assert(!takes || lane.bits.j < entered(gr), s"[${BinProperty.Delivery.name}] a pair of group $gr left that never entered")
    when(takes) { delivered(gr) := delivered(gr) + 1.U }
  }
  for (lane <- out.bits.pairs) assert(!(out.fire && lane.valid) || lane.bits.i < p.groups.U, s"[${BinProperty.Delivery.name}] a pair of no group left")
  // Lanes are filled lowest first.
  for (k <- 1 until p.pairsPerBeat)
    assert(!out.valid || !out.bits.pairs(k).valid || out.bits.pairs(k - 1).valid, s"[${BinProperty.Delivery.name}] a beat's lanes are not filled lowest first")
  val empty = merge.io.empty && serializers.map(_.io.empty).reduce(_ && _)
  for (gr <- 0 until p.groups)
    assert(!empty || delivered(gr) === entered(gr), s"[${BinProperty.Delivery.name}] the output path is empty, but a pair of group $gr never left")
}
