package bpaccel

import chisel3._
import chisel3.util._
import chiseltest._
import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import scala.util.Random

/** [[RegisteredHeadQueue]] against the library's `Queue(flow = true)` it
  * stands in for: both on the same random traffic, cycle by cycle.
  */
class RegisteredHeadQueueSpec extends AnyFlatSpec with ChiselScalatestTester with Matchers {

  class BothQueues(entries: Int) extends Module {
    val enq        = IO(Flipped(Decoupled(UInt(8.W))))
    val deqReady   = IO(Input(Bool()))
    val libraryDeq = IO(Output(Valid(UInt(8.W))))
    val libraryEnqReady = IO(Output(Bool()))
    val registeredDeq   = IO(Output(Valid(UInt(8.W))))
    val registeredEnqReady = IO(Output(Bool()))
    val holds = IO(Output(Bool()))

    private val library = Module(new Queue(UInt(8.W), entries, flow = true))
    private val registered = Module(new RegisteredHeadQueue(UInt(8.W), entries))
    for (q <- Seq(library.io.enq, registered.io.enq)) {
      q.valid := enq.valid
      q.bits  := enq.bits
    }
    enq.ready := library.io.enq.ready
    library.io.deq.ready    := deqReady
    registered.io.deq.ready := deqReady
    libraryDeq.valid := library.io.deq.valid
    libraryDeq.bits  := library.io.deq.bits
    libraryEnqReady  := library.io.enq.ready
    registeredDeq.valid := registered.io.deq.valid
    registeredDeq.bits  := registered.io.deq.bits
    registeredEnqReady  := registered.io.enq.ready
    holds := registered.io.holds
    // `holds`: the library queue held an entry at the cycle's start.
    chisel3.assert(registered.io.holds === (library.io.count =/= 0.U), "holds is not the library queue's non-empty")
  }

  behavior of "RegisteredHeadQueue"

  for (entries <- Seq(1, 2, 3, 5, 63)) {
    it should s"give the library flow queue's ready, valid and bits every cycle with $entries entries" in {
      test(new BothQueues(entries)) { c =>
        val rnd = new Random(entries)
        var accepted = 0
        // Phases of mostly-full and mostly-empty traffic reach both ends of the queue.
        for (phase <- 0 until 8; _ <- 0 until 300) {
          val fill = if (phase % 2 == 0) 0.8 else 0.3
          c.enq.valid.poke(rnd.nextDouble() < fill)
          c.enq.bits.poke(rnd.nextInt(256).U)
          c.deqReady.poke(rnd.nextDouble() < 1.0 - fill + 0.1)
          c.registeredEnqReady.expect(c.libraryEnqReady.peek())
          val valid = c.libraryDeq.valid.peek()
          c.registeredDeq.valid.expect(valid)
          if (valid.litToBoolean) c.registeredDeq.bits.expect(c.libraryDeq.bits.peek())
          if (c.enq.valid.peek().litToBoolean && c.libraryEnqReady.peek().litToBoolean) accepted += 1
          c.clock.step()
        }
        accepted should be > 500 // the traffic moves entries through, not only stalls
      }
    }
  }

  it should "be a wire with no entries" in {
    test(new RegisteredHeadQueue(UInt(8.W), 0)) { c =>
      c.io.enq.valid.poke(true.B)
      c.io.enq.bits.poke(42.U)
      c.io.deq.ready.poke(false.B)
      c.io.deq.valid.expect(true.B)
      c.io.deq.bits.expect(42.U)
      c.io.enq.ready.expect(false.B)
      c.io.deq.ready.poke(true.B)
      c.io.enq.ready.expect(true.B)
      c.io.holds.expect(false.B)
    }
  }
}
