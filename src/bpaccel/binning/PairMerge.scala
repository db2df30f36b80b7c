package bpaccel.binning

import chisel3._
import chisel3.util._

/** A group's hit queue and serializer: hit beats (one schedule cycle's hits)
  * wait in a queue whose room the engine's credits count; the head beat's
  * pairs leave one a cycle, lowest lane first, and the beat is dropped after
  * its last.
  */
class HitSerializer(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val hits  = Flipped(Valid(new HitBeat(p)))
    val out   = Decoupled(new BinPair(p))
    val freed = Output(Bool()) // a beat left the queue (its credit returns)
    val empty = Output(Bool())
  })
  val queue = Module(new Queue(new HitBeat(p), p.hitQueueDepth))
  queue.io.enq.valid := io.hits.valid
  queue.io.enq.bits  := io.hits.bits
  assert(!io.hits.valid || queue.io.enq.ready, "a group's hit queue overflowed: its credits are wrong")
  val sent = RegInit(0.U(p.g.W))
  val left = queue.io.deq.bits.hit.asUInt & ~sent
  val lane = PriorityEncoderOH(left)
  val last = (left & ~lane) === 0.U
  io.out.valid := queue.io.deq.valid
  io.out.bits  := Mux1H(lane, queue.io.deq.bits.pairs)
  val drop = if (p.has(BinningFault.SerializerDropsBeat)) queue.io.deq.valid else io.out.fire && last
  queue.io.deq.ready := drop
  when(io.out.fire) { sent := Mux(last, 0.U, sent | lane) }
  io.freed := queue.io.deq.fire
  io.empty := !queue.io.deq.valid
}

/** Round robin among `n` requesters: grants the first one after the last
  * grant (cyclically), the lowest first after a reset or `restart`.
  */
class RoundRobin(n: Int) extends Module {
  val io = IO(new Bundle {
    val restart = Input(Bool())
    val request = Input(Vec(n, Bool()))
    val take    = Input(Bool()) // the grant is used in this cycle
    val grant   = Output(UInt(n.W)) // one-hot, or 0 without a request
  })
  val last = RegInit((n - 1).U(log2Ceil(n).max(1).W))
  val after = VecInit((0 until n).map(k => io.request(k) && k.U > last)).asUInt
  io.grant := Mux(after.orR, PriorityEncoderOH(after), PriorityEncoderOH(io.request.asUInt))
  when(io.take && io.grant.orR) { last := OHToUInt(io.grant) }
  when(io.restart) { last := (n - 1).U }
}

/** Merges the groups' pairs into beats of up to pairsPerBeat: cluster c
  * serves groups c, c + P, ... round robin, one pair a cycle into its queue
  * (mergeQueueDepth pairs); each cycle the output queue (as many beats) takes the heads of all
  * cluster queues at once, lowest cluster first in the beat's lowest lanes.
  */
class PairMerge(p: BinningParams) extends Module {
  private val lanes = p.pairsPerBeat
  val io = IO(new Bundle {
    val restart = Input(Bool())
    val groups  = Vec(p.groups, Flipped(Decoupled(new BinPair(p))))
    val out     = Decoupled(new PairBeat(p))
    val empty   = Output(Bool()) // nothing in the cluster or output queues
  })
  val clusters = (0 until lanes).map { c =>
    val members = p.clusterGroups(c)
    val arbiter = Module(new RoundRobin(members.length))
    val queue   = Module(new Queue(new BinPair(p), p.mergeQueueDepth))
    arbiter.io.restart := io.restart
    arbiter.io.request := VecInit(members.map(io.groups(_).valid))
    val room = if (p.has(BinningFault.ClusterTakesWhenFull)) true.B else queue.io.enq.ready
    arbiter.io.take    := room
    queue.io.enq.valid := arbiter.io.grant.orR && room
    queue.io.enq.bits  := Mux1H(arbiter.io.grant, members.map(io.groups(_).bits))
    for ((gr, k) <- members.zipWithIndex) io.groups(gr).ready := room && arbiter.io.grant(k)
    queue
  }
  val output = Module(new Queue(new PairBeat(p), p.mergeQueueDepth))
  val heads  = clusters.map(_.io.deq)
  val offered = heads.map(_.valid)
  output.io.enq.valid := offered.reduce(_ || _)
  // Lane k of the beat takes the k-th cluster that offers a pair.
  // Each cluster's rank is its own count of the clusters before it that offer (a tree each, not one chain of adders).
  val rank = offered.indices.map(c => if (c == 0) 0.U else PopCount(offered.take(c)))
  for (k <- 0 until lanes) {
    val picks = heads.indices.map(c => offered(c) && rank(c) === k.U)
    output.io.enq.bits.pairs(k).valid := picks.reduce(_ || _)
    output.io.enq.bits.pairs(k).bits  := Mux1H(picks, heads.map(_.bits))
  }
  for (h <- heads) h.ready := output.io.enq.ready
  io.out <> output.io.deq
  io.empty := !offered.reduce(_ || _) && !output.io.deq.valid
}
