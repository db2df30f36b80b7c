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
  val lanes = Seq.fill(w)(Module(new FreeSlotQueue(new BinEntry(p), p.laneQueueDepth)))
  val beats = Module(new Queue(UInt(w.W), p.maskQueueDepth))

  io.in.room.beat  := beats.io.enq.ready
  io.in.room.lanes := VecInit(lanes.map(_.io.enq.ready))
  beats.io.enq.valid := io.in.push
  beats.io.enq.bits  := VecInit(io.in.offer.map(_.valid)).asUInt
  for ((q, e) <- lanes.zip(io.in.offer)) {
    q.io.enq.valid := io.in.push && e.valid
    q.io.enq.bits  := e.bits
  }
  assert(!io.in.push || (io.in.room.beat && lanes.zip(io.in.offer).map { case (q, e) => !e.valid || q.io.enq.ready }.reduce(_ && _)),
    "entries were pushed into a group without room")

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

/** chisel3.util.Queue (no flow, no pipe) but for one thing: the slot at the
  * tail takes `enq.bits` in every cycle in which the queue is not full,
  * whether `enq.valid` or not (that slot holds nothing yet). So `enq.valid`,
  * which the intake decides across all groups in its cycle, moves only the
  * tail pointer and reaches none of the data bits' enables. The lane queues
  * use it: 4 x 2 x 73 data bits in each of the 32 groups by default.
  */
class FreeSlotQueue[T <: Data](gen: T, entries: Int) extends Module {
  require(entries >= 1, s"FreeSlotQueue needs at least one entry, got $entries")
  val io = IO(new Bundle {
    val enq = Flipped(Decoupled(gen))
    val deq = Decoupled(gen)
  })
  private def next(ptr: UInt): UInt = Mux(ptr === (entries - 1).U, 0.U, ptr + 1.U)
  val ram       = Mem(entries, gen)
  val enqPtr    = RegInit(0.U(log2Ceil(entries).max(1).W))
  val deqPtr    = RegInit(0.U(log2Ceil(entries).max(1).W))
  val maybeFull = RegInit(false.B)
  val ptrMatch  = enqPtr === deqPtr
  val full      = ptrMatch && maybeFull
  io.enq.ready := !full
  io.deq.valid := !(ptrMatch && !maybeFull)
  io.deq.bits  := ram(deqPtr)
  when(!full) { ram(enqPtr) := io.enq.bits }
  when(io.enq.fire) { enqPtr := next(enqPtr) }
  when(io.deq.fire) { deqPtr := next(deqPtr) }
  when(io.enq.fire =/= io.deq.fire) { maybeFull := io.enq.fire }
}
