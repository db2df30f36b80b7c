package bpaccel.shell

import chisel3._
import chisel3.util._

/** The front of the input as 32-bit words (see [[InputWords]]). */
class WordWindow(p: ShellParams) extends Bundle {
  private val k = p.wordsPerBeat
  val words = Vec(p.itemWords, UInt(32.W))
  /** Words buffered (the window shows the first itemWords of them). */
  val count = UInt(log2Ceil(p.parserBufferWords + 1).W)
  /** Word i is the last of its packet (the last word of a beat with TLAST). */
  val last = Vec(p.itemWords, Bool())
  /** Words from the front to the end of its beat, the front word included (1 .. k). */
  val restOfBeat = UInt(log2Ceil(k + 1).W)
  /** Those words are all zero. */
  val restZero = Bool()
  /** The front word's beat carried TLAST. */
  val beatLast = Bool()
}

/** Turns beats of k words into a window on the next words of the input.
  *
  * A circular buffer of `parserBufferWords` words in beat-sized slots: a
  * beat is written whole into the next free slot (taken only while a whole
  * slot is free, a test on registers alone), and the consumer takes any
  * number of words from the front each cycle. Packets start on a fresh
  * beat, so a word's position in its beat is its position in the buffer
  * modulo k.
  */
class InputWords(p: ShellParams) extends Module {
  private val k     = p.wordsPerBeat
  private val size  = p.parserBufferWords
  private val slots = size / k
  require(slots >= 2 && isPow2(size), "the word buffer holds at least two beats, a power of two of words")
  val io = IO(new Bundle {
    val in      = Flipped(Decoupled(new InputBeat(p.streamBits)))
    val window  = Output(new WordWindow(p))
    val consume = Input(UInt(log2Ceil(size + 1).W))
  })
  val buffer    = Reg(Vec(size, UInt(32.W)))
  val slotLast  = Reg(Vec(slots, Bool()))
  val readPtr   = RegInit(0.U(log2Ceil(size).W))
  val writeSlot = RegInit(0.U(log2Ceil(slots).W))
  val count     = RegInit(0.U(log2Ceil(size + 1).W))

  io.in.ready := count <= (size - k).U
  when(io.in.fire) {
    for (s <- 0 until slots; j <- 0 until k) when(writeSlot === s.U) { buffer(s * k + j) := io.in.bits.data(32 * j + 31, 32 * j) }
    slotLast(writeSlot) := io.in.bits.last
    writeSlot := writeSlot + 1.U
  }
  assert(io.consume <= count, "the parser took more words than the buffer holds")
  readPtr := readPtr + io.consume
  count   := count - io.consume + Mux(io.in.fire, k.U, 0.U)

  private val offset = if (k == 1) 0.U else readPtr(log2Ceil(k) - 1, 0)
  private val slot   = readPtr >> log2Ceil(k)
  for (i <- 0 until p.itemWords) {
    val at = readPtr + i.U
    io.window.words(i) := buffer(at)
    io.window.last(i)  := slotLast(at >> log2Ceil(k)) && (if (k == 1) true.B else at(log2Ceil(k) - 1, 0).andR)
  }
  io.window.count      := count
  io.window.restOfBeat := k.U - offset
  private val beatWords = VecInit.tabulate(k)(j => VecInit.tabulate(slots)(s => buffer(s * k + j))(slot))
  io.window.restZero := (0 until k).map(j => j.U < offset || beatWords(j) === 0.U).reduce(_ && _)
  io.window.beatLast := slotLast(slot)
}
