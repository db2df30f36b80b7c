package bpaccel

import chisel3._
import chisel3.util._
import chiseltest._
import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import scala.util.Random

/** [[HeadRegisterQueue]] against the library's `Queue(flow = true, hasFlush = true)`,
  * which it replaces in the stream's reader: both on the same random traffic,
  * every output compared every cycle.
  */
class HeadRegisterQueueSpec extends AnyFlatSpec with ChiselScalatestTester with Matchers {

  class QueueOutputs(entries: Int) extends Bundle {
    val enqReady = Bool()
    val deqValid = Bool()
    val deqBits  = UInt(8.W)
    val count    = UInt(log2Ceil(entries + 1).W)
  }

  /** Both queues on the same inputs; the library's outputs beside the new one's. */
  class BothQueues(entries: Int) extends Module {
    private val gen = UInt(8.W)
    private val libraryQueue = Module(new Queue(gen, entries, flow = true, hasFlush = true))
    private val registers = Module(new HeadRegisterQueue(gen, entries))
    val enqValid = IO(Input(Bool()))
    val enqBits  = IO(Input(gen))
    val deqReady = IO(Input(Bool()))
    val flush    = IO(Input(Bool()))
    val mine     = IO(Output(new QueueOutputs(entries)))
    val library  = IO(Output(new QueueOutputs(entries)))
    for ((q, out) <- Seq((registers.io, mine), (libraryQueue.io, library))) {
      q.enq.valid   := enqValid
      q.enq.bits    := enqBits
      q.deq.ready   := deqReady
      q.flush.get   := flush
      out.enqReady := q.enq.ready
      out.deqValid := q.deq.valid
      out.deqBits  := Mux(q.deq.valid, q.deq.bits, 0.U) // bits are only defined while valid
      out.count    := q.count
    }
  }

  behavior of "HeadRegisterQueue"

  for (entries <- Seq(1, 2, 3, 5, 8))
    it should s"behave as Queue(flow = true, hasFlush = true) cycle for cycle with $entries entries" in {
      test(new BothQueues(entries)) { dut =>
        val rnd = new Random(entries)
        for (cycle <- 0 until 3000) {
          // Phases of mostly-full and mostly-empty traffic, so both ends are reached.
          val busy = (cycle / 200) % 2 == 0
          dut.enqValid.poke((rnd.nextInt(4) < (if (busy) 3 else 1)).B)
          dut.enqBits.poke(rnd.nextInt(256).U)
          dut.deqReady.poke((rnd.nextInt(4) < (if (busy) 1 else 3)).B)
          dut.flush.poke((rnd.nextInt(50) == 0).B)
          withClue(s"cycle $cycle: ") {
            dut.mine.enqReady.peek().litValue shouldBe dut.library.enqReady.peek().litValue
            dut.mine.deqValid.peek().litValue shouldBe dut.library.deqValid.peek().litValue
            dut.mine.deqBits.peek().litValue shouldBe dut.library.deqBits.peek().litValue
            dut.mine.count.peek().litValue shouldBe dut.library.count.peek().litValue
          }
          dut.clock.step()
        }
      }
    }
}
