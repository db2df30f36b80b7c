package bpaccel

import chisel3._
import chisel3.util._

/** Flow-through FIFO of result beats: a beat that meets an empty queue and a
  * ready consumer passes in the same cycle, so a never-stalling consumer adds
  * no latency. Entries are registers (a small LUT/flip-flop array), and
  * `count` feeds the sequencer's credit check.
  */
class ResultQueue(p: AccelParams) extends Module {
  private val depth = p.resultQueueDepth
  val io = IO(new Bundle {
    val enq   = Flipped(Decoupled(new ResultBeat(p)))
    val deq   = Decoupled(new ResultBeat(p))
    val count = Output(UInt(log2Ceil(depth + 1).W))
  })

  val entries = Reg(Vec(depth, new ResultBeat(p)))
  val head    = RegInit(0.U(log2Ceil(depth).W))
  val tail    = RegInit(0.U(log2Ceil(depth).W))
  val count   = RegInit(0.U(log2Ceil(depth + 1).W))
  val empty   = count === 0.U

  private def next(ptr: UInt): UInt = Mux(ptr === (depth - 1).U, 0.U, ptr + 1.U)

  io.enq.ready := count =/= depth.U
  io.deq.valid := !empty || io.enq.valid
  io.deq.bits  := Mux(empty, io.enq.bits, entries(head))
  io.count     := count

  val bypass  = empty && io.deq.ready
  val doEnq   = io.enq.fire && !bypass
  val doDeq   = io.deq.fire && !empty
  when(doEnq) {
    entries(tail) := io.enq.bits
    tail          := next(tail)
  }
  when(doDeq) { head := next(head) }
  count := count + doEnq.asUInt - doDeq.asUInt
}
