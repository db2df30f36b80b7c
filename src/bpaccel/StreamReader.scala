package bpaccel

import chisel3._
import chisel3.util._

/** A box in the stream engine, whether its object belongs to set B (always,
  * in a triangular run; meaningful in the window only) and, with the debug
  * port, the object index it came from.
  */
class StreamEntry(p: AccelParams) extends Bundle {
  val box = UInt(p.memoryWidth.W)
  val inB = Bool()
  val tag = UInt((if (p.debugPort) p.indexWidth else 0).W)
}

object StreamEntry {
  def tag(p: AccelParams, index: UInt): UInt = if (p.debugPort) index else 0.U(0.W)
}

/** The stream engine's memory and its reader: the loaded boxes go into the
  * coordinate memory, and a run's stream R (see [[StreamEngine]]) from R[m]
  * on comes out of it, read ahead into a small queue whose head register is
  * the window's entry.
  *
  * The memory holds two banks: every accepted start turns the writes to the
  * other bank, and its run reads the bank its boxes went to, so a batch
  * loads its next cell while the current one runs.
  *
  * The memory and its output registers run freely (no enable, no
  * multiplexer after the block RAM); reads are issued while the queue has
  * credits, and each issue takes one entry. Reading starts with the run, so
  * the first object reaches the head register readLatency cycles later, and
  * the reader then stays ahead: an issue always finds its object there.
  */
class StreamReader(p: AccelParams) extends Module {
  private val m = p.m
  val io = IO(new Bundle {
    val write   = Flipped(Valid(new LoadWrite(p))) // from the loader
    val prepare = Flipped(Valid(new RunRequest(p))) // a start was accepted
    val launch  = Input(Bool())                     // the run starts reading
    val bipartiteLeft = Input(UInt(log2Ceil(p.capacity + 2 * m).W)) // the run's constant (StreamControl)
    val active  = Input(Bool())                     // a run is under way
    val issue   = Input(Bool())                     // the schedule takes the head entry
    /** The loaded box, registered: the memory's write and the head registers take it. */
    val loaded = Valid(new LoadWrite(p))
    val head   = Output(new StreamEntry(p))
  })

  // Registered, and sampled every cycle, valid or not, so that neither the
  // load handshake nor an enable reaches the 200 flip-flops or the block
  // RAM's write port (docs/fpga.md).
  val loadedBox = Wire(Valid(new LoadWrite(p)))
  loadedBox.valid := RegNext(io.write.valid, false.B)
  loadedBox.bits  := RegNext(io.write.bits)
  io.loaded := loadedBox

  val writeBank  = RegInit(false.B)
  val readBank   = RegInit(false.B)
  val loadedBank = RegNext(writeBank) // the bank each box was accepted for
  when(io.prepare.valid) {
    writeBank := !writeBank
    readBank  := writeBank
  }
  private def row(bank: Bool, index: UInt): UInt = Cat(bank, index.pad(p.indexWidth))

  val memory = new CoordinateMemory(p.memoryStyle, p.memoryRows, p.memoryWidth)
  memory.write(loadedBox.valid, row(loadedBank, loadedBox.bits.index), loadedBox.bits.box.asUInt)

  // The head register, a one-entry pipe stage behind the queue: the queue's
  // LUT RAM, read behind its pointer, must not feed the window directly.
  // Written out, not a one-entry Queue, whose one-row memory of tags let z3
  // answer with a model ChiselTest's formal backend cannot read back.
  val readQueue = Module(new Queue(new StreamEntry(p), p.readLatency + 1, flow = true, hasFlush = true))
  val headValid = RegInit(false.B)
  val headEntry = Reg(new StreamEntry(p))
  io.head := headEntry
  val readsInFlight = Wire(UInt(log2Ceil(p.readLatency + 1).W))
  // Queue slots not yet taken or claimed by a read in flight, as a register
  // (the queue's count plus the reads in flight, compared with its depth,
  // stood in front of every reader register).
  private val readDepth = p.readLatency + 2
  val readCredits = RegInit(readDepth.U(log2Ceil(readDepth + 1).W))
  val readEvent   = io.active && readCredits =/= 0.U
  readCredits := readCredits - readEvent.asUInt + io.issue.asUInt

  val rObj       = Reg(UInt(p.indexWidth.W)) // object read at the next read event
  val rLeft      = Reg(UInt(p.countWidth.W)) // objects after rObj in its block's stream
  val rBlockLeft = Reg(UInt(p.countWidth.W)) // n-2-base of rObj's block
  val rBase      = Reg(UInt(p.countWidth.W))
  val runSplit   = Reg(UInt(p.countWidth.W)) // 0: a triangular run
  // The stream's tests, one read ahead as the schedule's are: rLeft == 0, rBlockLeft >= m.
  val rBlockEnd     = Reg(Bool())
  val rHasNextBlock = Reg(Bool())
  val rALeft        = Reg(UInt(p.countWidth.W)) // lastA-base of rObj's block
  // A bipartite block's stream jumps from its prefix (base+1 .. base+2m-1,
  // which carries the next A block past the top lane) to max(base+2m, na):
  // the A objects in between meet nothing of B (Schedule). A triangular
  // run's jump target is base+2m, the next object anyway.
  val rAtJump     = Reg(Bool())               // rObj is the prefix's last object, base+2m-1
  val rBeforeJump = Reg(UInt(p.countWidth.W)) // base+2m-2
  val rJumpTo     = Reg(UInt(p.indexWidth.W)) // max(base+2m, na): read only while below n, so an index
  when(readEvent) {
    when(!rBlockEnd) {
      rObj      := Mux(rAtJump, rJumpTo, rObj + 1.U)
      rAtJump   := !rAtJump && rObj === rBeforeJump
      rLeft     := rLeft - 1.U
      rBlockEnd := rLeft === 1.U
    }.elsewhen(rHasNextBlock) {
      // Next block's stream: objects base+m+1 .. base+3m-1, then max(base+3m, na) .. n-1.
      val nextLeft = StreamEngine.minOf(rBlockLeft - m.U, io.bipartiteLeft)
      rBase         := rBase + m.U
      rObj          := rBase + (m + 1).U
      rLeft         := nextLeft
      rBlockLeft    := rBlockLeft - m.U
      rBlockEnd     := rBlockLeft === m.U // nextLeft == 0: bipartiteLeft >= 1
      rALeft        := rALeft - m.U
      rHasNextBlock := rALeft >= (2 * m).U
      rAtJump       := (m == 1).B
      rBeforeJump   := rBase + (3 * m - 2).U
      rJumpTo       := StreamEngine.maxOf(rBase + (3 * m).U, runSplit)(p.indexWidth - 1, 0)
    } // past the last block the stream is never compared: hold
  }
  // While a run reads its bank, boxes are written only to the other one (a
  // run's first read comes two cycles after its last box was taken, its
  // write one), so no read meets a write of its row: the emitted memory
  // needs no collision bypass (NoCollisionMemories).
  assert(!(loadedBox.valid && readEvent && loadedBank === readBank), "a box was written to the bank the stream reads")

  // The read, then memoryOutputStages registers; the data joins where the
  // memory delivers it (the first register may sit in the block RAM).
  val data = memory.read(readEvent, row(readBank, rObj))
  val read = Wire(Valid(new StreamEntry(p)))
  read.valid    := RegNext(readEvent, false.B)
  read.bits.tag := RegNext(StreamEntry.tag(p, rObj))
  read.bits.inB := RegNext(rObj >= runSplit)
  read.bits.box := (if (memory.latency == 1) data else DontCare)
  val readStages = (1 to p.memoryOutputStages).scanLeft(read) { (before, stage) =>
    val registered = Pipe(before)
    if (stage != memory.latency - 1) registered
    else {
      val withData = Wire(Valid(new StreamEntry(p)))
      withData          := registered
      withData.bits.box := data
      withData
    }
  }
  readsInFlight := PopCount(readStages.map(_.valid))
  readQueue.io.enq.valid := readStages.last.valid
  readQueue.io.enq.bits  := readStages.last.bits
  readQueue.io.deq.ready := !headValid || io.issue
  when(readQueue.io.deq.fire) { headEntry := readQueue.io.deq.bits }
  readQueue.io.flush.get := io.launch // drop what the last run read ahead
  headValid := !io.launch && (readQueue.io.deq.fire || (headValid && !io.issue))
  assert(!io.issue || headValid, "the stream's reader fell behind the schedule")
  assert(!readQueue.io.enq.valid || readQueue.io.enq.ready, "the stream's read queue overflowed")
  // A run is launched only after its boxes were loaded, at least two cycles
  // after the last run's last read left its pipeline, so the flush drops
  // every read of that run and all credits come back.
  assert(!io.launch || readsInFlight === 0.U, "a read of the last run was in flight at a launch")
  assert(
    readQueue.io.count +& headValid.asUInt +& readsInFlight +& readCredits === readDepth.U || io.launch,
    "the stream's read credits do not match the queue"
  )

  when(io.prepare.valid) {
    val count     = io.prepare.bits.count
    val split     = io.prepare.bits.split
    val bipartite = split =/= 0.U
    val jumps     = split > (2 * m).U
    val nb        = count - split // count for a triangular run
    runSplit   := split
    rBase      := 0.U
    rBlockLeft := count - 2.U
    rALeft     := Mux(bipartite, split - 1.U, count - 2.U)
    // R[m], block 0's stream object m: object m+1 while m+1 lies in its
    // prefix (m >= 2), else the jump's target. Without it (n < m + 2) no
    // later block exists and the stream past block 0 is never compared.
    val longBlock = count >= (m + 2).U
    val jumpTo0   = Mux(jumps, split, (2 * m).U) // max(2m, split)
    rObj  := Mux(longBlock, (if (m >= 2) (m + 1).U else jumpTo0), 0.U)
    // Objects after R[m] in block 0's stream: left0 - m.
    val jumpLeft = if (m >= 2) nb + (m - 2).U else nb - 1.U
    rLeft := Mux(longBlock, Mux(jumps, jumpLeft, count - (m + 2).U), 0.U)
    // ... which is 0 for n = m + 2 and, at m = 1, for a jump to the last object.
    val jumpEndsBlock = if (m == 1) jumps && nb === 1.U else false.B
    rBlockEnd     := !longBlock || (!jumps && count === (m + 2).U) || jumpEndsBlock
    rHasNextBlock := Mux(bipartite, split > m.U, longBlock) // lastA >= m
    rAtJump       := (m == 2).B // object m+1 = 2m-1 ends the prefix
    rBeforeJump   := (2 * m - 2).U
    rJumpTo       := jumpTo0(p.indexWidth - 1, 0)
  }
  when(io.launch) { readCredits := readDepth.U }
}
