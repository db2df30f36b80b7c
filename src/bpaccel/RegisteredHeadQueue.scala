package bpaccel

import chisel3._
import chisel3.util._

/** A queue of `entries` that behaves as `Queue(enq, entries, flow = true)`
  * cycle for cycle (same ready, valid and bits on every input sequence), but
  * whose head is a register: the output comes from that register or, when
  * the queue is empty, from the input, never from the memory behind it.
  *
  * The library queue reads its head from its memory with the dequeue
  * pointer, and a LUT RAM's asynchronous read in front of the consumer was
  * seed m = 8's critical path with `ecp5-outreg` memories (116.9 MHz: the
  * batch front end's tail queue -> the head cell's `left`). Here the
  * memory's read only refills the head register: the rest of the entries
  * wait in a library `Queue` of `entries - 1`, which is never read while
  * the head register is empty.
  *
  * `holds` is the head register's valid bit: the queue held an entry at the
  * cycle's start.
  */
class RegisteredHeadQueue[T <: Data](gen: T, entries: Int) extends Module {
  require(entries >= 0, s"a queue holds at least 0 entries, got $entries")
  val io = IO(new Bundle {
    val enq   = Flipped(Decoupled(gen))
    val deq   = Decoupled(gen)
    val holds = Output(Bool())
  })

  if (entries == 0) {
    // As the library's queue of no entries: a wire.
    io.deq <> io.enq
    io.holds := false.B
  } else {
    val headValid = RegInit(false.B)
    val head      = Reg(gen)
    io.deq.valid := headValid || io.enq.valid
    io.deq.bits  := Mux(headValid, head, io.enq.bits)
    io.holds     := headValid

    // Invariant: the rest holds entries only while the head register does.
    val restValid = WireDefault(false.B)
    val restBits  = Wire(gen)
    restBits := DontCare
    // An arrival passes the head register: it goes to the rest unless the
    // head register is empty after this cycle with nothing older to refill it.
    val arrivalToRest = headValid && !(io.deq.ready && !restValid)
    io.enq.ready := true.B
    if (entries > 1) {
      val rest = Module(new Queue(gen, entries - 1))
      rest.io.enq.valid := io.enq.valid && arrivalToRest
      rest.io.enq.bits  := io.enq.bits
      rest.io.deq.ready := headValid && io.deq.ready
      restValid         := rest.io.deq.valid
      restBits          := rest.io.deq.bits
      when(arrivalToRest) { io.enq.ready := rest.io.enq.ready }
    } else {
      // The head register is all there is: as the library's queue, no
      // arrival while it is full, even in a cycle that empties it.
      io.enq.ready := !headValid
    }

    when(!headValid || io.deq.ready) { // the head register is free after this cycle
      when(restValid) {
        head := restBits
      }.elsewhen(io.enq.fire && !(io.deq.ready && !headValid)) { // an arrival that does not flow through
        head := io.enq.bits
      }
      headValid := restValid || (io.enq.fire && !(io.deq.ready && !headValid))
    }
  }
}
