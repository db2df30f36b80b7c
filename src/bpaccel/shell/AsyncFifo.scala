package bpaccel.shell

import chisel3._
import chisel3.util._

/** A FIFO between two clock domains, with gray-coded pointers.
  *
  * The writer keeps its binary and gray write pointers, the reader its own;
  * each side sees the other's gray pointer through two flip-flops
  * (`*_sync0`, `*_sync1`: constrain the path into `*_sync0` as a
  * clock-domain crossing, docs/integration.md). The storage is written in
  * the writer's domain and read, behind the reader's pointer, in the
  * reader's; an entry is read only after its pointer crossed, so it is
  * stable by then. Every output is a flip-flop or storage read behind a
  * flip-flop: `enq.ready` and `deq.valid` come from the pointers alone.
  *
  * Each side has its own reset; both must be held in reset together before
  * either leaves it, and the writer may write only once the reader is out
  * of reset ([[BpaccelShell]] sequences both).
  */
class AsyncFifo[T <: Data](gen: T, depth: Int) extends RawModule {
  require(isPow2(depth) && depth >= 4, s"an asynchronous FIFO needs a power-of-two depth of at least 4, got $depth")
  private val ptrBits = log2Ceil(depth) + 1
  val io = IO(new Bundle {
    val enqClock = Input(Clock())
    val enqReset = Input(Bool())
    val enq      = Flipped(Decoupled(gen))
    val deqClock = Input(Clock())
    val deqReset = Input(Bool())
    val deq      = Decoupled(gen)
  })

  private def toGray(b: UInt): UInt = b ^ (b >> 1)
  private def synchronize(gray: UInt, name: String): UInt = {
    val s0 = RegNext(gray, 0.U(ptrBits.W)).suggestName(s"${name}_sync0")
    RegNext(s0, 0.U(ptrBits.W)).suggestName(s"${name}_sync1")
  }

  // Written on the writer's clock, read without a clock behind the reader's pointer: the
  // shape of a LUT RAM with an asynchronous read port (TRELLIS_DPR16X4, Xilinx distributed RAM).
  private val storage = Mem(depth, gen)

  private val writeGray = Wire(UInt(ptrBits.W))
  private val readGray  = Wire(UInt(ptrBits.W))

  withClockAndReset(io.enqClock, io.enqReset) {
    val bin  = RegInit(0.U(ptrBits.W))
    val gray = RegInit(0.U(ptrBits.W))
    val readSeen = synchronize(readGray, "readGray")
    // Full: the pointers differ in their two top bits only (gray code).
    val full = gray === (readSeen ^ (3.U(2.W) << (ptrBits - 2)))
    io.enq.ready := !full
    when(io.enq.fire) {
      storage.write(bin(ptrBits - 2, 0), io.enq.bits, io.enqClock)
      bin  := bin + 1.U
      gray := toGray(bin + 1.U)
    }
    writeGray := gray
  }

  withClockAndReset(io.deqClock, io.deqReset) {
    val bin  = RegInit(0.U(ptrBits.W))
    val gray = RegInit(0.U(ptrBits.W))
    val writeSeen = synchronize(writeGray, "writeGray")
    io.deq.valid := gray =/= writeSeen
    io.deq.bits  := storage.read(bin(ptrBits - 2, 0))
    when(io.deq.fire) {
      bin  := bin + 1.U
      gray := toGray(bin + 1.U)
    }
    readGray := gray
  }
}
