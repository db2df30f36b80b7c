package bpaccel.binning

import chisel3._
import chisel3.util._

/** Queues a group's entries from the intake and writes them one a cycle, in
  * stream order, whatever the timing: a queue per intake lane holds the
  * entries, a queue of beats holds which lanes each beat used, and the
  * writer takes the head beat's lanes lowest first.
  */
class GroupWriter(p: BinningParams) extends Module {
  private val w = p.intakeBoxes
  val io = IO(new Bundle {
    val in         = Flipped(new GroupPush(p))
    val frameStart = Input(Bool())
    val write      = Valid(new BinEntry(p)) // the entry written in this cycle, at address `count`
    val count      = Output(UInt(p.entryCountWidth.W)) // entries written so far in this frame
    val idle       = Output(Bool()) // nothing queued, and nothing written in the last cycle
  })
  val lanes = Seq.fill(w)(Module(new Queue(new BinEntry(p), p.laneQueueDepth)))
  val beats = Module(new Queue(UInt(w.W), p.maskQueueDepth))

  io.in.room := beats.io.enq.ready && lanes.zip(io.in.offer).map { case (q, e) => !e.valid || q.io.enq.ready }.reduce(_ && _)
  beats.io.enq.valid := io.in.push
  beats.io.enq.bits  := VecInit(io.in.offer.map(_.valid)).asUInt
  for ((q, e) <- lanes.zip(io.in.offer)) {
    q.io.enq.valid := io.in.push && e.valid
    q.io.enq.bits  := e.bits
  }
  assert(!io.in.push || io.in.room, "entries were pushed into a group without room")

  val written = RegInit(0.U(w.W)) // lanes of the head beat already written
  val left    = beats.io.deq.bits & ~written
  val lane    = PriorityEncoderOH(left)
  val writes  = beats.io.deq.valid
  val lastOfBeat = (left & ~lane) === 0.U
  beats.io.deq.ready := writes && lastOfBeat
  for ((q, k) <- lanes.zipWithIndex) q.io.deq.ready := writes && lane(k)
  assert(!writes || Mux1H(lane, lanes.map(_.io.deq.valid)), "a group's beat names a lane whose queue is empty")
  when(writes) { written := Mux(lastOfBeat, 0.U, written | lane) }

  val count = RegInit(0.U(p.entryCountWidth.W))
  when(writes) { count := count + 1.U }
  when(io.frameStart) { count := 0.U }

  io.write.valid := writes
  io.write.bits  := Mux1H(lane, lanes.map(_.io.deq.bits))
  io.count := count
  io.idle  := !beats.io.deq.valid && !RegNext(writes, false.B)
}
