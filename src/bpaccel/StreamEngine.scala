package bpaccel

import chisel3._
import chisel3.util._

/** The stream architecture: the seed's schedule from one memory read a cycle.
  *
  * Schedule (the seed's): block b compares A objects base+k (base = b*m) with
  * B objects s+k, s = base+1 .. n-1, lane k masked once s+k >= n. So the B
  * objects of consecutive cycles form one stream R: block 0's objects
  * 1 .. n-1, then block 1's m+1 .. n-1, and so on. In issue cycle t the
  * window, an m-deep shift register, holds R[t .. t+m-1] (lane k = object
  * s+k); each issue shifts it by one lane and takes R[t+m] from the single
  * memory read port at the top. A block's last m-1 lanes already hold the
  * next block's first objects, so blocks follow each other without a bubble.
  *
  * A blocks sit in registers (`a`). The next block's A objects base+m+k pass
  * the window's top lane in cycle k of the current block; `aNext`, a shift
  * chain entered at the top, takes each there (so object base+m+k ends in
  * lane k after m shifts) and is copied into `a` at the block change.
  *
  * Objects 0 .. m are kept, as they are loaded, in m + 1 head registers of
  * their own (`headRegs`): a shift chain beside the window, entered at the
  * top, so the loaded box goes to one register and every other wire is
  * local (written by lane, the box went to all m + 1 and congested stream
  * m = 32's routing). The cycle after a start copies them at once: lane
  * k + 1 into window lane k, lane k into `aNext` lane k. So a run needs no
  * window shifts of its own before it issues, and a batch's next cell loads
  * all its boxes, these included, while the current cell runs. Only the
  * window and `aNext` have a multiplexer in front of them (the lane above,
  * or the entry / the window's top lane at the top, else the head
  * register); `a` loads from `aNext`.
  *
  * A run of L < m + 1 loaded boxes leaves its objects d = m + 1 - L lanes
  * up the chain (object j in lane j + d; d is the loader's head pad, read
  * with the start), and so in the window and the A block: a short run's
  * lanes k < d are masked, and its lane k compares objects k - d and
  * k - d + s. The mask leaves in the engine's lane order; the beat's bases
  * are moved down instead, iBase = base - d and jBase = s - d modulo
  * 2^indexWidth, so bit k is still the pair (iBase + k, jBase + k) taken
  * modulo 2^indexWidth, and a set bit (k >= d) never wraps. That costs a
  * subtract beside the control's registers, where a shift of the mask by
  * d lanes on its way out was the FPGA's critical path (docs/fpga.md).
  * Runs of more than one block have n >= m + 2 objects, so d = 0 for them.
  *
  * Bipartite runs (split na > 0: only objects 0 .. na-1 against na .. n-1)
  * keep this shape: blocks run for the A objects alone, and a block's
  * stream jumps from its first 2m-1 objects (which still carry the next A
  * block past the top lane) to max(base+2m, na); lanes whose B object is
  * in A, or whose A object is past na-1, are masked (see Schedule).
  *
  * Startup after the start: the first readLatency reads travel to the
  * window's entry. The lanes (head chain, window, aNext, a) act
  * StreamEngine.LaneLag cycles after the control decides (see
  * `replicatedEnable`). Pipeline: the lanes' lag, comparator register, AND
  * register.
  */
class StreamEngine(p: AccelParams) extends Engine(p) {
  private val m = p.m
  private val W = 6 * p.keyWidth

  /** A box, whether its object belongs to set B (always, in a triangular
    * run; meaningful in the window only) and, with the debug port, the
    * object index it came from.
    */
  class Entry extends Bundle {
    val box = UInt(W.W)
    val inB = Bool()
    val tag = UInt((if (p.debugPort) p.indexWidth else 0).W)
  }
  private def tagOf(index: UInt): UInt = if (p.debugPort) index else 0.U(0.W)

  // ---- the loaded boxes, registered: for the memory's write port and the window ----
  // Sampled every cycle, valid or not (every use checks the valid): Pipe's
  // enable put the load port's valid-and-ready in front of these 200
  // flip-flops (stream m = 64's critical path, 72.2 MHz, 12.6 ns routing).
  // The memory's write port takes them from here too: the load handshake
  // drove its write enable directly (stream m = 32's critical path,
  // 101.0 MHz: load ready -> the block RAMs' write enable, 8.5 ns of wire).
  val loadedBox = Wire(Valid(new LoadWrite(p)))
  loadedBox.valid := RegNext(io.write.valid, false.B)
  loadedBox.bits  := RegNext(io.write.bits)

  // ---- memory banks: a batch loads its next cell into one while a run reads the other ----
  // Every accepted start turns the writes to the other bank; its run reads
  // the bank its boxes went to. Each box carries the bank it was accepted for.
  val writeBank  = RegInit(false.B)
  val readBank   = RegInit(false.B)
  val loadedBank = RegNext(writeBank)
  when(io.prepare.valid) {
    writeBank := !writeBank
    readBank  := writeBank
  }
  private def row(bank: Bool, index: UInt): UInt = Cat(bank, index.pad(p.indexWidth))

  // ---- coordinate memory: one row of six keys per object (its read is below) ----
  // Top-level vals, so the memory keeps its plain name (module mem_<rows>x<width>).
  private val rows = p.memoryRows // two banks, so a row is the bank bit over the index
  val mem = Option.when(p.memoryStyle == MemoryStyle.Inferred)(SyncReadMem(rows, UInt(W.W)))
  for (mem <- mem) when(loadedBox.valid) { mem.write(row(loadedBank, loadedBox.bits.index), loadedBox.bits.box.asUInt) }
  val registeredMem =
    Option.when(p.memoryStyle == MemoryStyle.Ecp5OutputRegister)(Module(new RegisteredReadMemory(rows, W)))

  // ---- run state ----
  val starting = RegInit(false.B)
  val issuing  = RegInit(false.B)
  val active   = starting || issuing // a run is under way
  val primeLeft = Reg(UInt(log2Ceil(p.readLatency + 1).W)) // cycles until the first read reaches the entry
  val issue     = issuing && advance

  // The next values of the flags behind the wide enables (window, A block):
  // the enables are computed from them a cycle ahead, see `replicatedEnable`.
  // `*Carry`: the next value unless a run is launched in this cycle.
  val startingCarry = WireDefault(starting)
  val issuingNext   = WireDefault(issuing)
  val issueNext     = issuingNext && io.room // `issue` in the next cycle (advance is io.room registered)

  // ---- read side: the stream R from R[m] on, read ahead into a small queue ----
  // The memory and its output registers run freely (no enable, no
  // multiplexer after the block RAM); reads are issued while the queue has
  // room for them, and each issue takes one entry. Reading starts with the
  // run, so the first object reaches the queue's head register readLatency
  // cycles later, and the reader then stays ahead: an issue always finds its
  // object there. The head register feeds the window's entry: the queue's
  // LUT RAM, read behind its pointer, fed lane m-1 directly (stream m = 32's
  // critical path, 100.8 MHz, 8.4 ns of wire).
  val readQueue = Module(
    new Queue(new Entry, p.readLatency + 1, flow = true, hasFlush = true)
  )
  // The head register, a one-entry pipe stage behind the queue. Written out,
  // not a one-entry Queue: that queue's one-row memory of tags let z3 answer
  // a counterexample with a model ChiselTest's formal backend cannot read
  // back ("(lambda ((x!1 Bool)) x!1)"), and synthesis makes it this register anyway.
  val headValid = RegInit(false.B)
  val headEntry = Reg(new Entry)
  val readsInFlight = Wire(UInt(log2Ceil(p.readLatency + 1).W))
  // Queue slots not yet taken or claimed by a read in flight, kept as a
  // register: comparing the queue's count plus the reads in flight with its
  // depth put the queue pointers, an adder and a comparator in front of every
  // reader register (the m = 8 critical path).
  private val readDepth = p.readLatency + 2
  val readCredits = RegInit(readDepth.U(log2Ceil(readDepth + 1).W))
  val readEvent   = active && readCredits =/= 0.U
  readCredits := readCredits - readEvent.asUInt + issue.asUInt
  val rObj       = Reg(UInt(p.indexWidth.W))  // object read at the next read event
  val rLeft      = Reg(UInt(p.countWidth.W))  // objects after rObj in its block's stream
  val rBlockLeft = Reg(UInt(p.countWidth.W))  // n-2-base of rObj's block
  val rBase      = Reg(UInt(p.countWidth.W))
  // The run's constants, from its start: its split (0: triangular), and the
  // stream objects after a bipartite block's first, 2m-2+nb (nb = n - split,
  // so n + 2m - 2 for a triangular run: never the smaller of the two below).
  val runSplit      = Reg(UInt(p.countWidth.W))
  val bipartiteLeft = Reg(UInt(log2Ceil(p.capacity + 2 * m).W))
  private def minOf(a: UInt, b: UInt): UInt = Mux(a < b, a, b)
  private def maxOf(a: UInt, b: UInt): UInt = Mux(a > b, a, b)
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
      val nextLeft = minOf(rBlockLeft - m.U, bipartiteLeft)
      rBase         := rBase + m.U
      rObj          := rBase + (m + 1).U
      rLeft         := nextLeft
      rBlockLeft    := rBlockLeft - m.U
      rBlockEnd     := rBlockLeft === m.U // nextLeft == 0: bipartiteLeft >= 1
      rALeft        := rALeft - m.U
      rHasNextBlock := rALeft >= (2 * m).U
      rAtJump       := (m == 1).B
      rBeforeJump   := rBase + (3 * m - 2).U
      rJumpTo       := maxOf(rBase + (3 * m).U, runSplit)(p.indexWidth - 1, 0)
    } // past the last block the stream is never compared: hold
  }
  // readsNeverMeetWrites: while a run reads its bank, boxes are written only
  // to the other one (a run's first read comes two cycles after its last box
  // was taken, its write one), so no read meets a write of its row, which
  // lets the emitted memory drop the block RAM's collision bypass
  // (NoCollisionMemories).
  assert(!(loadedBox.valid && readEvent && loadedBank === readBank), "a box was written to the bank the stream reads")
  // ---- the memory's read ----
  val read = Wire(Valid(new Entry))
  read.valid    := RegNext(readEvent, false.B)
  read.bits.tag := RegNext(tagOf(rObj))
  read.bits.inB := RegNext(rObj >= runSplit)
  // The read, then memoryOutputStages registers; the first may sit in the block RAM.
  val readStages = (mem, registeredMem) match {
    case (Some(mem), _) =>
      read.bits.box := mem.read(row(readBank, rObj), readEvent)
      Seq.iterate(read, p.memoryOutputStages + 1)(x => Pipe(x))
    case (_, Some(mem)) =>
      mem.io.writeEnable := loadedBox.valid
      mem.io.writeRow    := row(loadedBank, loadedBox.bits.index)
      mem.io.writeData   := loadedBox.bits.box.asUInt
      mem.io.readEnable  := readEvent
      mem.io.readRow     := row(readBank, rObj)
      read.bits.box := DontCare // only inside the memory
      val first = Wire(Valid(new Entry))
      first.valid    := RegNext(read.valid, false.B)
      first.bits.tag := RegEnable(read.bits.tag, read.valid)
      first.bits.inB := RegEnable(read.bits.inB, read.valid)
      first.bits.box := mem.io.readData
      read +: Seq.iterate(first, p.memoryOutputStages)(x => Pipe(x))
    case _ => throw new IllegalStateException("one of the two memories exists")
  }
  readsInFlight := PopCount(readStages.map(_.valid))
  readQueue.io.enq.valid := readStages.last.valid
  readQueue.io.enq.bits  := readStages.last.bits
  readQueue.io.deq.ready := !headValid || issue
  when(readQueue.io.deq.fire) { headEntry := readQueue.io.deq.bits }
  readQueue.io.flush.get := io.launch.valid // drop what the last run read ahead
  headValid := !io.launch.valid && (readQueue.io.deq.fire || (headValid && !issue))
  assert(!issue || headValid, "the stream's reader fell behind the schedule")
  assert(!readQueue.io.enq.valid || readQueue.io.enq.ready, "the stream's read queue overflowed")
  // A run is launched only after its boxes were loaded, at least two cycles
  // after the last run's last read left its pipeline, so the flush drops
  // every read of that run and all credits come back.
  assert(!io.launch.valid || readsInFlight === 0.U, "a read of the last run was in flight at a launch")
  assert(
    readQueue.io.count +& headValid.asUInt +& readsInFlight +& readCredits === readDepth.U || io.launch.valid,
    "the stream's read credits do not match the queue"
  )

  starting := io.launch.valid || startingCarry
  issuing  := issuingNext
  // No look-ahead of the per-lane enables reads this cycle's start or the
  // load port's handshake with it: the host's start register reached them
  // through the start's acceptance and the load port's ready (stream m = 64's
  // critical path at 92b097e, 78.8 MHz: host start -> load ready -> a head
  // chain enable copy; taking it off that look-ahead alone moved it to the
  // next one, d26d030). Each look-ahead below says why it needs no start.

  // ---- objects 0 .. m: kept in a chain of head registers as they are loaded ----
  // Each head object enters the top register and moves every register
  // below it down one lane, so after L of them object j sits in lane
  // j + m + 1 - min(L, m + 1). The shift's enable is registered once per
  // lane beside the box (like the window's), from the loader's head flag. A
  // batch writes its next cell's head here while the current cell runs: the
  // start copied these registers in the cycle after it, and the next cell's
  // boxes come later.
  val headRegs  = Reg(Vec(m + 1, new Entry))
  val headWrite = loadedBox.valid && loadedBox.bits.head
  // Its look-ahead takes a box offered for a write even in a cycle whose
  // start or batch count refuses it (`writeOffered`): that spurious shift
  // comes the cycle after the clear, when the copy below reads the chain's
  // old values, and only moves boxes of the numbering the clear ended (the
  // loader checks that only a clear refuses an offered box).
  val headShift = replicatedEnable(
    "headShift",
    next = io.writeOffered && io.write.bits.head,
    now = headWrite,
    copies = m + 1,
    unless = RegNext(io.loadClear, false.B)
  )
  val laneBox = toLanes(loadedBox.bits)
  for (k <- 0 to m) when(headShift(k)) {
    if (k == m) {
      headRegs(k).box := laneBox.box.asUInt
      headRegs(k).inB := DontCare // set by lane at the copy into the window
      headRegs(k).tag := tagOf(laneBox.index)
    } else headRegs(k) := headRegs(k + 1)
  }
  // The window and aNext follow the head registers in every cycle after one
  // with no run active (starting or issuing), so in the cycle after a start
  // too, when they copy the run's objects 0 .. m for good: its last head box
  // was written in the start's cycle at the latest. Following needs no
  // start in the look-ahead (copying in the cycle after each start did: the
  // host's start reached these enable copies); what is copied while idle is
  // never compared. A batch's next cell writes the head registers only while
  // the current one is active, so the copy keeps the current cell's.
  val copyNext =
    if (p.has(Fault.HeadCopiedLate)) !active && !io.prepare.valid // misses the cycle after the start
    else !active
  val copying  = RegNext(copyNext, false.B)
  val headCopy = replicatedEnable("headCopy", next = copyNext, now = copying)
  // headCopiedBeforeWritten: no head box of the next cell is written before
  // the copy of this one (the front end takes the next count at the start,
  // so its first box is written two cycles later at the earliest).
  val copyPending = RegInit(false.B)
  when(io.prepare.valid) { copyPending := true.B }.elsewhen(copying) { copyPending := false.B }
  assert(!(copyPending && headWrite && !io.prepare.valid),
    "a head register was written before the start's copy of it")

  // ---- the window: lane k holds object s+k ----
  val window = Reg(Vec(m, new Entry))
  val entry  = toLanes(headEntry)
  // One enable per lane for both of the window's writes, the copy and the
  // shift, so that the copy's flag only selects the source: as two enables,
  // their OR was a LUT before each lane's clock enables (stream m = 128's
  // critical path, 71.0 MHz: `headCopy_replica68` -> that LUT beside lane
  // 68's aNext, placed 60 columns away, 13.3 ns of routing).
  val windowWrite = replicatedEnable(
    "windowWrite",
    next = copyNext || (issuingNext && (io.room || p.has(Fault.LookaheadIgnoresRoom).B)),
    now = copying || issue
  )
  // The window takes objects 1 .. m from the head registers at the copy.
  // Lane k then holds object k+1-d, in B when k+1 >= split + d (`splitLane`, 0 for a triangular run).
  private val copiedToLane = if (p.has(Fault.HeadCopyOffByOne)) 0 else 1
  val splitLane = Reg(UInt(p.countWidth.W))
  val laneSplit = toLanes(splitLane)
  for (k <- 0 until m) when(windowWrite(k)) {
    when(headCopy(k)) {
      window(k)     := headRegs(k + copiedToLane)
      window(k).inB := (k + 1).U >= laneSplit
    }.otherwise {
      window(k) := (if (k == m - 1) entry else window(k + 1))
    }
  }
  assert(!(copying && issue), "the window was copied and shifted in one cycle")

  // ---- A blocks ----
  val a     = Reg(Vec(m, new Entry))
  val aNext = Reg(Vec(m, new Entry))
  // Block 0's A objects come from the head registers at the copy; later
  // blocks': cycle k of a block finds object base+m+k in the top lane, and
  // the first m issues of a block shift it into aNext's top lane, moving the
  // ones before it down. (Written by lane, the top lane's 192 bits went to
  // all m lanes of aNext, across the window: with the head registers'
  // broadcast, stream m = 64 did not route.)
  // A count, not a one-hot of m bits: the block change's set of that
  // one-hot sent issue && hasNextBlock to 128 flip-flops, which pulled its
  // LUT across the device (stream m = 128's critical path, 55.5 MHz:
  // issuing -> advance -> that LUT at column 4 -> the enable of `s`, 16.8 ns of routing).
  val captureLeft    = RegInit(0.U(log2Ceil(m + 1).W)) // of the block's first m issues, those still to come
  val captureLast    = RegInit(false.B) // captureLeft == 1, as a register
  val capturing      = RegInit(false.B) // captureLeft =/= 0, as a register
  val capturingCarry = WireDefault(capturing) // its next value unless a start is accepted
  val capturingNext  = Mux(io.prepare.valid, true.B, capturingCarry)
  capturing := capturingNext
  private def restartCapture(): Unit = {
    captureLeft := m.U
    captureLast := (m == 1).B
  }
  assert(capturing === (captureLeft =/= 0.U) && captureLast === (captureLeft === 1.U),
    "the capture flags do not match their count")
  // Each lane's enable is a register computed a cycle ahead, as the window's
  // and the A block's are: `issuing` reached lane k's 192 enables through
  // issue && capture(k) (stream m = 64's critical path, 83.7 MHz, 11.0 ns of wire).
  // The look-ahead reads the capture flag's start-free next value: in a cycle
  // that accepts a start no run is active, so issueNext is false anyway.
  // Like the window's, one enable for the copy and the shift.
  val aNextWrite = replicatedEnable(
    "aNextWrite",
    next = copyNext || (issueNext && capturingCarry),
    now = copying || (issue && capturing)
  )
  for (k <- 0 until m) when(aNextWrite(k)) {
    when(headCopy(k)) {
      aNext(k) := headRegs(k)
    }.otherwise {
      aNext(k) := (if (k == m - 1) window(m - 1) else aNext(k + 1))
    }
  }

  // ---- the schedule ----
  val base      = Reg(UInt(p.countWidth.W))
  val s         = Reg(UInt(p.countWidth.W))
  val left      = Reg(UInt(p.countWidth.W)) // n-1-s: cycles after this one in the block
  val blockLeft = Reg(UInt(p.countWidth.W)) // n-2-base
  val nMinus1   = Reg(UInt(p.countWidth.W)) // s = n-1-left: lane 0 ends every block at object n-1
  // Blocks run while base <= lastA (n-2, or na-1 for a bipartite run); lane k's A object base+k-d is in A while k <= aTop.
  val aLeft     = Reg(UInt(p.countWidth.W)) // lastA-base
  val aTop      = Reg(UInt(p.countWidth.W)) // aLeft + headOffset
  // The run's lanes start `headOffset` lanes up (d above; 0 unless n < m + 2),
  // so lane k holds object s + k - d, which exists while k <= left + d = laneTop.
  val headOffset = Reg(UInt(log2Ceil(p.headObjects + 1).W))
  val laneTop    = Reg(UInt(p.countWidth.W))
  // The block-end test, computed one cycle ahead so that no comparison sits
  // between the issue and the enables of the A registers.
  val blockEnd     = Reg(Bool()) // left == 0
  val hasNextBlock = Reg(Bool()) // aLeft >= m
  // `*Carry`: the next value unless a start is accepted. The look-ahead of
  // aLoad reads these: a start is accepted only while no run is active, so
  // its issue term is false then anyway, and the start count's compares stay
  // out of it (stream m = 32's critical path after the launch's).
  val blockEndCarry     = WireDefault(blockEnd)
  val hasNextBlockCarry = WireDefault(hasNextBlock)
  val blockEndNext      = WireDefault(blockEndCarry)
  val hasNextBlockNext  = WireDefault(hasNextBlockCarry)
  blockEnd     := blockEndNext
  hasNextBlock := hasNextBlockNext
  assert(!io.prepare.valid || !active, "a start was accepted while a run was active")
  // Their next values, in turn, from flags kept a step ahead of the counters,
  // so that no comparison sits in the enables' look-ahead either (the path
  // advance -> issue -> blockEndNext -> aLoad's copies, stream m = 32).
  val leftIsOne          = Reg(Bool()) // left == 1
  val blockLeftIsM       = Reg(Bool()) // blockLeft == m
  val aLeftAtLeast2m     = Reg(Bool()) // aLeft >= 2m
  // The cycle after an accepted start, which sets the registers that
  // depend on block 0's length (see the start below); read from the next
  // cycle on, when no issue has come yet (readLatency >= 2).
  val settling = RegNext(io.prepare.valid, false.B)
  when(active && !settling) {
    assert(laneTop === left + headOffset && aTop === aLeft + headOffset && (headOffset === 0.U || !hasNextBlock),
      "the lanes' offset does not match the run")
    assert(s === nMinus1 - left, "the window's start does not match its count of cycles left")
    assert(leftIsOne === (left === 1.U) && blockLeftIsM === (blockLeft === m.U) &&
      aLeftAtLeast2m === (aLeft >= (2 * m).U), "the block-end flags do not match their counters")
  }
  // The A block is copied from aNext in the startup's cycles after its first
  // (aNext holds block 0 from the end of the first: the copy above), and at
  // each block change. readLatency >= 2 gives the startup a second cycle.
  require(p.readLatency >= 2)
  val launched = RegNext(io.launch.valid, false.B) // the startup's first cycle
  val aLoad = replicatedEnable(
    "aLoad",
    next = startingCarry || (issueNext && blockEndCarry && hasNextBlockCarry),
    now = (starting && !launched) || (issue && blockEnd && hasNextBlock)
  )
  for (k <- 0 until m) when(aLoad(k)) { a(k) := aNext(k) }
  when(starting) {
    when(primeLeft =/= 0.U) { primeLeft := primeLeft - 1.U }
    when(primeLeft <= 1.U) {
      startingCarry := false.B
      issuingNext  := true.B
    }
  }
  when(issue) {
    when(!blockEnd) {
      s        := s + 1.U
      left     := left - 1.U
      laneTop  := laneTop - 1.U
      leftIsOne := left === 2.U
      blockEndCarry := leftIsOne
      when(capturing) { captureLeft := captureLeft - 1.U }
      captureLast    := captureLeft === 2.U
      capturingCarry := capturing && !captureLast
    }.elsewhen(hasNextBlock) {
      // A bipartite block that jumps starts with lane 0 at virtual object
      // n-1-left: the lanes from the jump on hold it + k, the prefix's lanes
      // before it hold A objects and are masked.
      val nextLeft = minOf(blockLeft - m.U, bipartiteLeft)
      base         := base + m.U
      s            := nMinus1 - nextLeft
      left         := nextLeft
      laneTop      := nextLeft // headOffset = 0: this run has n >= m + 2
      blockLeft    := blockLeft - m.U
      aLeft        := aLeft - m.U
      aTop         := aLeft - m.U
      leftIsOne          := nextLeft === 1.U
      blockLeftIsM       := blockLeft === (2 * m).U
      aLeftAtLeast2m     := aLeft >= (3 * m).U
      blockEndCarry     := blockLeftIsM // nextLeft == 0: bipartiteLeft >= 1
      hasNextBlockCarry := aLeftAtLeast2m
      restartCapture()
      capturingCarry := true.B
    }.otherwise {
      issuingNext := false.B
    }
  }
  // Every accepted start loads the run's n-derived registers, launched or
  // not: they are read only while starting or issuing, so the start's
  // decoded error checks (the launch) reach only the flags below, not all of
  // these enables (stream m = 32's critical path).
  assert(!io.launch.valid || (io.prepare.valid && io.prepare.bits.count === io.launch.bits), "a launch without its start")
  // At most one add or compare of the start's count and split per register
  // here: the start's bits come through the batch front end's multiplexer,
  // and block 0's length min(n-2, 2m-2+nb) computed in the start's cycle
  // took bipartite runs to stream m = 64's critical path (70.0 MHz: batch
  // active -> count - split -> min -> laneTop, four carry chains). So
  // the registers only the first issue reads take it in the next cycle,
  // `settling`, from registers; so does aTop = lastA + d. (Written as
  // count + (headPad - 2) in the start's cycle, firtool narrowed
  // headPad - 2 to five bits, so it never wrapped: the host's Verilog
  // broke where ChiselTest's passed.)
  val bigSplit = Reg(Bool()) // split > 2m: block 0's stream jumps, and it takes 2m-2+nb cycles after its first
  when(settling) {
    val left0 = Mux(bigSplit, bipartiteLeft, blockLeft) // min(n-2, 2m-2+nb)
    s         := nMinus1 - left0
    left      := left0
    laneTop   := left0 + headOffset
    aTop      := aLeft + headOffset
    leftIsOne := left0 === 1.U
  }
  when(io.prepare.valid) {
    val count = io.prepare.bits.count // >= 2 when it launches
    val split = io.prepare.bits.split // 0, or 1 .. count-1 when it launches
    val bipartite = split =/= 0.U
    val jumps     = split > (2 * m).U
    val nb        = count - split // count for a triangular run
    runSplit      := split
    bigSplit      := jumps
    bipartiteLeft := nb +& (2 * m - 2).U
    splitLane     := Mux(bipartite, split + io.headPad, 0.U)
    primeLeft := p.readLatency.U
    base      := 0.U
    nMinus1   := count - 1.U
    blockLeft := count - 2.U
    aLeft     := Mux(bipartite, split - 1.U, count - 2.U) // lastA
    headOffset := io.headPad
    blockLeftIsM       := count === (m + 2).U
    aLeftAtLeast2m     := Mux(bipartite, jumps, count >= (2 * m + 2).U)
    blockEndNext     := count === 2.U // block 0 ends at once: left0 == 0
    hasNextBlockNext := Mux(bipartite, split > (m + (if (p.has(Fault.SkipSecondBlockAtMPlus2)) 1 else 0)).U,
      count >= (m + (if (p.has(Fault.SkipSecondBlockAtMPlus2)) 3 else 2)).U) // lastA >= m
    restartCapture()
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
  when(io.launch.valid) { readCredits := readDepth.U }

  // ---- comparators: registered compare, then registered AND ----
  class Meta extends Bundle {
    val iBase    = UInt(p.indexWidth.W)
    val jBase    = UInt(p.indexWidth.W)
    val laneMask = UInt(m.W) // by lane of the engine (the run's lane k - headOffset)
    val probeI   = Vec(m, UInt(p.indexWidth.W)) // only with the debug port
    val probeJ   = Vec(m, UInt(p.indexWidth.W))
  }
  // The issue's own fields, in control time, each lane's mask without its
  // B flag computed beside the counters; the lanes get them LaneLag cycles later,
  // as registers.
  val laneHasObjects = VecInit(Seq.tabulate(m)(k =>
    // Lane k holds object s+k-d, which exists while n - s > k - d, i.e.
    // laneTop >= k: from a register directly, not from n - s (that
    // subtraction in front of the compares was stream m = 32's critical
    // path, 105.5 MHz). Lanes below d hold no object of the run.
    // A bipartite run also masks lanes whose B object is in A, and those
    // past the last A object.
    headOffset <= k.U &&
      (if (p.has(Fault.LaneMaskOneTooWide)) laneTop +& 1.U >= k.U else laneTop >= k.U) &&
      (aTop >= k.U || p.has(Fault.BipartiteALanesUnmasked).B))).asUInt
  // With a reset: the result queue's credits count these stages in flight.
  val laneIssue   = ShiftRegisters(issue, StreamEngine.LaneLag, false.B, true.B)
  val laneObjects = toLanes(laneHasObjects)
  val meta = Wire(new Meta)
  // Lane k holds objects base + k - d and s + k - d: the beat's bases are
  // moved down by d (modulo 2^indexWidth; lanes below d never compare, so
  // no hit wraps), here in control time, from the control's registers, so
  // that the mask needs no shift on its way out (see the class comment).
  private def movedDown(x: UInt): UInt =
    (if (p.has(Fault.ShortRunBasesNotMoved)) x else x - headOffset)(p.indexWidth - 1, 0)
  meta.iBase    := toLanes(movedDown(base))
  meta.jBase    := toLanes(movedDown(s))
  meta.laneMask := laneObjects & VecInit(window.map(_.inB)).asUInt
  if (p.debugPort) {
    // The objects each lane really holds, from the tags that travelled with
    // the data, by lane of the engine as the hit mask is.
    meta.probeI := VecInit(a.map(_.tag))
    meta.probeJ := VecInit(window.map(_.tag))
  } else {
    meta.probeI := DontCare
    meta.probeJ := DontCare
  }
  private def boxOf(e: Entry): Aabb = e.box.asTypeOf(new Aabb(p.keyWidth))
  // Six comparator results per lane, registered before the AND.
  val compare = Module(new ComparatorArray(p))
  compare.io.a := VecInit(a.map(boxOf))
  compare.io.b := VecInit(window.map(boxOf))
  val compared = RegNext(compare.io.compares)
  val atCompare = sampled(laneIssue.last, meta)
  val hits = hitRegisters(ComparatorArray.hits(compared) & atCompare.bits.laneMask)
  val atAnd     = sampled(atCompare.valid, atCompare.bits)
  require(p.pipelineLatency == StreamEngine.LaneLag + 2) // the lanes' lag, compare, AND

  io.activity.active   := active
  io.activity.issued   := issue
  io.activity.stalled  := issuing && !advance
  io.activity.inFlight := PopCount(laneIssue :+ atCompare.valid :+ atAnd.valid)
  io.activity.retired  := atAnd.valid

  /** `Pipe` without the enable on its bits: they are sampled every cycle,
    * since only a valid stage's are read. Pipe's enable sent `issue` to the
    * m lane mask registers of each stage.
    */
  private def sampled[T <: Data](valid: Bool, bits: T): Valid[T] = {
    val stage = Wire(Valid(chiselTypeOf(bits)))
    stage.valid := RegNext(valid, false.B)
    stage.bits  := RegNext(bits)
    stage
  }

  /** `x` as the lanes see it: [[StreamEngine.LaneLag]] cycles late (see [[replicatedEnable]]). */
  private def toLanes[T <: Data](x: T): T =
    (1 to StreamEngine.LaneLag).foldLeft(x) { (value, _) =>
      val late = Reg(chiselTypeOf(value)) // of the value's own type, its width not left to inference
      late := value
      late
    }

  /** One register per lane (`copies` of them) holding `now` of
    * [[StreamEngine.LaneLag]] cycles ago, computed from `next` (its value a
    * cycle ahead) and checked to be so except where `unless` held in the
    * cycle of that `now` (a look-ahead that may differ there says why that
    * is harmless): each copy drives one lane's 192 clock enables, where one
    * net drove all 192m (stream m = 64's critical path: 12.4 ns of routing to
    * about 12,000 flip-flops). Synthesis merges identical registers unless
    * told otherwise; the FPGA flow keeps the copies by name (docs/fpga.md).
    *
    * The path to the copies is a chain, so that each cycle holds either
    * logic or a long wire, never both:
    *  - `<name>_replica_lead`: one register, beside the control, takes the
    *    look-ahead's logic (the issue, credit, block-end and capture flags);
    *  - `<name>_replica_group<g>`: one register per group of
    *    [[StreamEngine.LaneGroup]] lanes, at the end of the wire across the
    *    die;
    *  - `<name>_replica<k>`: each lane's copy.
    * So the lanes act LaneLag cycles after the control decides, and their
    * other inputs come through [[toLanes]]. With one cycle of lag the
    * look-ahead's logic and the wire to the far groups were one cycle
    * (stream m = 128's critical path, 60.6 MHz: `issuing` -> `advance`,
    * placed 40 rows away -> 4 LUT levels -> an `aNextShift` group register,
    * 14.8 ns of routing).
    */
  private def replicatedEnable(
    name: String,
    next: Bool,
    now: Bool,
    copies: Int = m,
    unless: Bool = false.B
  ): Seq[Bool] = {
    require(StreamEngine.LaneLag == 2, "the chain below is written for two cycles of lag")
    // The reset enters at the lead alone, never per lane or group: reset on
    // each copy sent the wrapper's reset register to every lane (stream
    // m = 64's critical path, 60.2 MHz, 15.6 ns of routing). A group or lane
    // register may hold anything in the first LaneLag cycles after a
    // one-cycle reset: no box has been loaded then (the first box is written
    // to a lane LaneLag + 1 cycles after it is offered), so what it shifts or
    // copies is never compared.
    val lead = RegNext(next, false.B).suggestName(s"${name}_replica_lead")
    val groups = Seq.tabulate((copies + StreamEngine.LaneGroup - 1) / StreamEngine.LaneGroup)(g =>
      RegNext(lead).suggestName(s"${name}_replica_group$g"))
    // What each copy is checked against, registered once for all of them.
    val afterReset = ShiftRegisters(reset.asBool, StreamEngine.LaneLag, true.B, true.B)
    val nowLate    = ShiftRegister(now, StreamEngine.LaneLag)
    val excused    = ShiftRegister(unless, StreamEngine.LaneLag) || afterReset.reduce(_ || _)
    Seq.tabulate(copies) { k =>
      val copy = RegNext(groups(k / StreamEngine.LaneGroup)).suggestName(s"${name}_replica$k")
      assert(copy === nowLate || excused, s"the look-ahead of $name is wrong")
      copy
    }
  }

  val outValid =
    if (p.has(Fault.RepeatLastBeat)) atAnd.valid || (RegNext(atAnd.valid, false.B) && !atAnd.valid) else atAnd.valid
  emit(outValid, atAnd.bits.iBase, atAnd.bits.jBase, atAnd.bits.laneMask, atAnd.bits.probeI, atAnd.bits.probeJ, hits)
}

object StreamEngine {
  /** Lanes served by one register of each enable's group stage. */
  val LaneGroup = 8

  /** Cycles by which the lanes act after the control decides (see replicatedEnable). */
  val LaneLag = 2
}
