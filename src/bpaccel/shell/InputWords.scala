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
  * Beats are kept whole in `slots` slots of a ring (a beat is taken only
  * while a whole slot is free, a test on registers alone), and the consumer
  * takes any number of words from the front each cycle. The window reads the
  * few beats it can reach (its first word's beat and the next ones, one slot
  * multiplexer each) and picks its words by the front's offset in its beat,
  * a k-way multiplexer per word: much less logic than a multiplexer per word
  * over the whole ring at wide beats. Packets start on a fresh beat, so a
  * word's position in its beat is its position in the ring modulo k.
  */
class InputWords(p: ShellParams) extends Module {
  private val k     = p.wordsPerBeat
  private val size  = p.parserBufferWords
  private val slots = size / k
  /** Beats a window can touch: its first word at offset k-1 and itemWords words. */
  private val reach = (k - 1 + p.itemWords + k - 1) / k
  require(slots >= 2 && isPow2(slots) && reach <= slots, "the ring holds at least two beats and every beat a window touches")
  val io = IO(new Bundle {
    val in      = Flipped(Decoupled(new InputBeat(p.streamBits)))
    val window  = Output(new WordWindow(p))
    val consume = Input(UInt(log2Ceil(size + 1).W))
  })
  val ring      = Reg(Vec(slots, Vec(k, UInt(32.W))))
  val slotLast  = Reg(Vec(slots, Bool()))
  val readPtr   = RegInit(0.U(log2Ceil(size).W))
  val writeSlot = RegInit(0.U(log2Ceil(slots).W))
  val count     = RegInit(0.U(log2Ceil(size + 1).W))

  io.in.ready := count <= (size - k).U
  when(io.in.fire) {
    ring(writeSlot)     := VecInit.tabulate(k)(j => io.in.bits.data(32 * j + 31, 32 * j))
    slotLast(writeSlot) := io.in.bits.last
    writeSlot := writeSlot + 1.U
  }
  assert(io.consume <= count, "the parser took more words than the buffer holds")
  readPtr := readPtr + io.consume
  count   := count - io.consume + Mux(io.in.fire, k.U, 0.U)

  private val offset = readPtr(log2Ceil(k) - 1, 0)
  private val slot   = readPtr >> log2Ceil(k)
  // The multiplexers are AND-OR trees, word by word: written as multiplexers of Vecs, firtool
  // folds them into multiplexers of arrays, which its lowering without packed arrays refuses.
  private def select(choice: UInt, options: Seq[UInt]): UInt = {
    val oneHot = UIntToOH(choice, options.length)
    options.zipWithIndex.map { case (o, s) => Fill(o.getWidth, oneHot(s)) & o }.reduce(_ | _)
  }
  private val beats = Seq.tabulate(reach) { b =>
    val at = (slot + b.U)(log2Ceil(slots) - 1, 0)
    (Seq.tabulate(k)(j => select(at, ring.map(_(j)))), slotLast(at))
  }
  private val words  = beats.flatMap(_._1)
  // Word w of the beats read ends its packet if it is its beat's last and that beat carried TLAST.
  private val lastAt = Seq.tabulate(words.length)(w => if (w % k == k - 1) beats(w / k)._2 else false.B)
  for (i <- 0 until p.itemWords) {
    io.window.words(i) := select(offset, Seq.tabulate(k)(o => words(o + i)))
    io.window.last(i)  := select(offset, Seq.tabulate(k)(o => lastAt(o + i))).asBool
  }
  io.window.count      := count
  io.window.restOfBeat := k.U - offset
  io.window.restZero   := (0 until k).map(j => j.U < offset || beats.head._1(j) === 0.U).reduce(_ && _)
  io.window.beatLast   := beats.head._2
}
