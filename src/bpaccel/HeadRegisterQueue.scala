package bpaccel

import chisel3._
import chisel3.util._

/** `Queue(gen, entries, flow = true, hasFlush = true)` with the same ports and
  * the same behaviour cycle for cycle, built from registers that shift
  * towards a fixed head: the oldest entry is always register 0, so `deq.bits`
  * is a register or, when the queue is empty, `enq.bits` (flow-through).
  *
  * `Queue` keeps its entries in a memory read at a pointer; on an FPGA that
  * is a LUT RAM whose read, behind its pointer registers, fed the stream's
  * 192-bit window entry (stream m = 32's critical path, 100.8 MHz: the read
  * queue's pointer -> LUT RAM -> window lane m-1, 8.4 ns of wire). For the
  * few entries the stream needs, registers cost little. `QueueSpec` checks
  * it against `Queue` under random traffic.
  */
class HeadRegisterQueue[T <: Data](gen: T, val entries: Int) extends Module {
  require(entries >= 1, s"HeadRegisterQueue needs at least one entry, got $entries")
  val io = IO(new QueueIO(gen, entries, hasFlush = true))

  private val slots = Reg(Vec(entries, gen))
  private val count = RegInit(0.U(log2Ceil(entries + 1).W))
  // count === 0, as a register of its own: it selects the flow-through for every bit of deq.
  private val empty = RegInit(true.B)

  io.enq.ready := count =/= entries.U
  io.deq.valid := !empty || io.enq.valid
  io.deq.bits  := Mux(empty, io.enq.bits, slots(0))
  io.count     := count

  // An entry that arrives at an empty queue and leaves in the same cycle is never stored.
  private val stores = io.enq.fire && !(empty && io.deq.ready)
  private val drops  = io.deq.fire && !empty
  private val writeAt = Mux(drops, count - 1.U, count)
  for (i <- 0 until entries) {
    when(stores && writeAt === i.U) {
      slots(i) := io.enq.bits
    }.elsewhen(drops) {
      if (i + 1 < entries) slots(i) := slots(i + 1)
    }
  }
  private val countNext = count + stores.asUInt - drops.asUInt
  count := countNext
  empty := countNext === 0.U
  when(io.flush.get) {
    count := 0.U
    empty := true.B
  }
}
