package bpaccel

import chisel3._
import chisel3.util._

/** One wide enable of the stream engine's lanes, as the control decides it:
  * `lead` is a register holding `now`, computed from its value a cycle
  * ahead; `unless` excuses a cycle in which the look-ahead may differ (see
  * [[StreamLanes]], which copies `lead` to every lane and checks the copies).
  */
class LaneEnable extends Bundle {
  val lead   = Bool()
  val now    = Bool()
  val unless = Bool()
}

/** The stream engine's schedule (see [[StreamEngine]]): the run's state and
  * counters, the block changes, and, for the lanes, each wide enable's lead
  * register, computed a cycle ahead from flags kept a step ahead of the
  * counters, and the issue's fields. Nothing here is per lane.
  *
  * No look-ahead reads this cycle's start or the load port's handshake with
  * it; each one says why it needs no start.
  */
class StreamControl(p: AccelParams) extends Module {
  private val m = p.m
  val io = IO(new Bundle {
    val prepare      = Flipped(Valid(new RunRequest(p)))
    val launch       = Flipped(Valid(UInt(p.countWidth.W)))
    val headPad      = Input(UInt(log2Ceil(p.headObjects + 1).W))
    val writeOffered = Input(Bool())               // the loader offers a box ...
    val offeredHead  = Input(Bool())               // ... that is a head object
    val loaded       = Flipped(Valid(new LoadWrite(p))) // the box written now (StreamReader)
    val loadClear    = Input(Bool())
    val room         = Input(Bool())               // room for an issue next cycle
    val advance      = Input(Bool())               // room for an issue now (room, registered)

    val active  = Output(Bool())
    val issuing = Output(Bool())
    val issue   = Output(Bool())
    /** The run's constant 2m-2+nb (nb = n - split; n + 2m - 2 for a triangular run). */
    val bipartiteLeft = Output(UInt(log2Ceil(p.capacity + 2 * m).W))

    val headShift   = Output(new LaneEnable) // the head chain shifts in a loaded head object
    val headCopy    = Output(new LaneEnable) // the window and aNext copy the head chain
    val windowWrite = Output(new LaneEnable) // the window copies or shifts
    val aNextWrite  = Output(new LaneEnable) // aNext copies or captures
    val aLoad       = Output(new LaneEnable) // the A block takes aNext
    /** The window's lane k takes its object as one of B when k + 1 >= splitLane (0 for a triangular run). */
    val splitLane = Output(UInt(p.countWidth.W))
    /** The issue's fields: lanes that hold objects of the run, and the beat's bases (moved down by the head pad). */
    val laneHasObjects = Output(UInt(m.W))
    val iBase          = Output(UInt(p.indexWidth.W))
    val jBase          = Output(UInt(p.indexWidth.W))
  })

  private def lead(name: String, next: Bool, now: Bool, unless: Bool = false.B): LaneEnable = {
    val e = Wire(new LaneEnable)
    // The reset enters here alone: no group or lane copy has one (StreamLanes).
    e.lead   := RegNext(next, false.B).suggestName(s"${name}_replica_lead")
    e.now    := now
    e.unless := unless
    e
  }

  // ---- run state ----
  val starting  = RegInit(false.B)
  val issuing   = RegInit(false.B)
  val active    = starting || issuing // a run is under way
  val primeLeft = Reg(UInt(log2Ceil(p.readLatency + 1).W)) // cycles until the first read reaches the entry
  val issue     = issuing && io.advance

  // The next values of the flags behind the wide enables, from which those
  // are computed a cycle ahead. `*Carry`: the next value unless a run is
  // launched in this cycle.
  val startingCarry = WireDefault(starting)
  val issuingNext   = WireDefault(issuing)
  val issueNext     = issuingNext && io.room // `issue` in the next cycle
  starting := io.launch.valid || startingCarry
  issuing  := issuingNext

  // ---- the head chain ----
  // Its look-ahead takes a box offered for a write even in a cycle whose
  // start or batch count refuses it (`writeOffered`): that spurious shift
  // comes the cycle after the clear, when the copy reads the chain's old
  // values, and only moves boxes of the numbering the clear ended (the
  // loader checks that only a clear refuses an offered box).
  val headWrite = io.loaded.valid && io.loaded.bits.head
  io.headShift := lead("headShift", next = io.writeOffered && io.offeredHead, now = headWrite,
    unless = RegNext(io.loadClear, false.B))
  // The window and aNext follow the head registers in every cycle after one
  // with no run active, so in the cycle after a start too, when they copy
  // the run's objects 0 .. m for good: its last head box was written in the
  // start's cycle at the latest. What is copied while idle is never
  // compared. A batch's next cell writes the head registers only while the
  // current one is active, so the copy keeps the current cell's.
  val copyNext =
    if (p.has(Fault.HeadCopiedLate)) !active && !io.prepare.valid // misses the cycle after the start
    else !active
  val copying = RegNext(copyNext, false.B)
  io.headCopy := lead("headCopy", next = copyNext, now = copying)
  // No head box of the next cell is written before the copy of this one (the
  // front end takes the next count at the start, so its first box is written
  // two cycles later at the earliest).
  val copyPending = RegInit(false.B)
  when(io.prepare.valid) { copyPending := true.B }.elsewhen(copying) { copyPending := false.B }
  assert(!(copyPending && headWrite && !io.prepare.valid),
    "a head register was written before the start's copy of it")

  // ---- the window: one enable for the copy and the shift, the copy's flag selects the source ----
  io.windowWrite := lead("windowWrite",
    next = copyNext || (issuingNext && (io.room || p.has(Fault.LookaheadIgnoresRoom).B)),
    now = copying || issue)
  val splitLane = Reg(UInt(p.countWidth.W))
  io.splitLane := splitLane
  assert(!(copying && issue), "the window was copied and shifted in one cycle")

  // ---- aNext: cycle k of a block finds object base+m+k in the window's top lane ----
  // A count, not a one-hot of m bits, so the block change sets few flip-flops.
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
  // The look-ahead reads the capture flag's start-free next value: in a cycle
  // that accepts a start no run is active, so issueNext is false anyway.
  io.aNextWrite := lead("aNextWrite", next = copyNext || (issueNext && capturingCarry),
    now = copying || (issue && capturing))

  // ---- the schedule ----
  val base      = Reg(UInt(p.countWidth.W))
  val s         = Reg(UInt(p.countWidth.W))
  val left      = Reg(UInt(p.countWidth.W)) // n-1-s: cycles after this one in the block
  val blockLeft = Reg(UInt(p.countWidth.W)) // n-2-base
  val nMinus1   = Reg(UInt(p.countWidth.W)) // s = n-1-left: lane 0 ends every block at object n-1
  // Blocks run while base <= lastA (n-2, or na-1 for a bipartite run); lane k's A object base+k-d is in A while k <= aTop.
  val aLeft     = Reg(UInt(p.countWidth.W)) // lastA-base
  val aTop      = Reg(UInt(p.countWidth.W)) // aLeft + headOffset
  // The run's lanes start `headOffset` lanes up (d, 0 unless n < m + 2),
  // so lane k holds object s + k - d, which exists while k <= left + d = laneTop.
  val headOffset = Reg(UInt(log2Ceil(p.headObjects + 1).W))
  val laneTop    = Reg(UInt(p.countWidth.W))
  // The block-end test, one cycle ahead, so that no comparison sits between
  // the issue and the A block's enables.
  val blockEnd     = Reg(Bool()) // left == 0
  val hasNextBlock = Reg(Bool()) // aLeft >= m
  // `*Carry`: the next value unless a start is accepted. The look-ahead of
  // aLoad reads these: a start is accepted only while no run is active, so
  // its issue term is false then anyway.
  val blockEndCarry     = WireDefault(blockEnd)
  val hasNextBlockCarry = WireDefault(hasNextBlock)
  val blockEndNext      = WireDefault(blockEndCarry)
  val hasNextBlockNext  = WireDefault(hasNextBlockCarry)
  blockEnd     := blockEndNext
  hasNextBlock := hasNextBlockNext
  assert(!io.prepare.valid || !active, "a start was accepted while a run was active")
  // Their next values, in turn, from flags kept a step ahead of the
  // counters, so that no comparison sits in the enables' look-ahead either.
  val leftIsOne      = Reg(Bool()) // left == 1
  val blockLeftIsM   = Reg(Bool()) // blockLeft == m
  val aLeftAtLeast2m = Reg(Bool()) // aLeft >= 2m
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
  // (aNext holds block 0 from the end of the first: the head copy), and at
  // each block change. readLatency >= 2 gives the startup a second cycle.
  require(p.readLatency >= 2)
  val launched = RegNext(io.launch.valid, false.B) // the startup's first cycle
  io.aLoad := lead("aLoad",
    next = startingCarry || (issueNext && blockEndCarry && hasNextBlockCarry),
    now = (starting && !launched) || (issue && blockEnd && hasNextBlock))
  when(starting) {
    when(primeLeft =/= 0.U) { primeLeft := primeLeft - 1.U }
    when(primeLeft <= 1.U) {
      startingCarry := false.B
      issuingNext   := true.B
    }
  }
  val bipartiteLeft = Reg(UInt(log2Ceil(p.capacity + 2 * m).W))
  io.bipartiteLeft := bipartiteLeft
  when(issue) {
    when(!blockEnd) {
      s         := s + 1.U
      left      := left - 1.U
      laneTop   := laneTop - 1.U
      leftIsOne := left === 2.U
      blockEndCarry := leftIsOne
      when(capturing) { captureLeft := captureLeft - 1.U }
      captureLast    := captureLeft === 2.U
      capturingCarry := capturing && !captureLast
    }.elsewhen(hasNextBlock) {
      // A bipartite block that jumps starts with lane 0 at virtual object
      // n-1-left: the lanes from the jump on hold it + k, the prefix's lanes
      // before it hold A objects and are masked.
      val nextLeft = StreamEngine.minOf(blockLeft - m.U, bipartiteLeft)
      base           := base + m.U
      s              := nMinus1 - nextLeft
      left           := nextLeft
      laneTop        := nextLeft // headOffset = 0: this run has n >= m + 2
      blockLeft      := blockLeft - m.U
      aLeft          := aLeft - m.U
      aTop           := aLeft - m.U
      leftIsOne      := nextLeft === 1.U
      blockLeftIsM   := blockLeft === (2 * m).U
      aLeftAtLeast2m := aLeft >= (3 * m).U
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
  // decoded error checks (the launch) reach only the flags above.
  assert(!io.launch.valid || (io.prepare.valid && io.prepare.bits.count === io.launch.bits), "a launch without its start")
  // At most one add or compare of the start's count and split per register
  // in the start's cycle (its bits come through the batch front end's
  // multiplexer): the registers only the first issue reads take block 0's
  // length, min(n-2, 2m-2+nb), in the next cycle, `settling`, from
  // registers; so does aTop = lastA + d.
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
    val count     = io.prepare.bits.count // >= 2 when it launches
    val split     = io.prepare.bits.split // 0, or 1 .. count-1 when it launches
    val bipartite = split =/= 0.U
    val jumps     = split > (2 * m).U
    val nb        = count - split // count for a triangular run
    bigSplit      := jumps
    bipartiteLeft := nb +& (2 * m - 2).U
    splitLane     := Mux(bipartite, split + io.headPad, 0.U)
    primeLeft     := p.readLatency.U
    base          := 0.U
    nMinus1       := count - 1.U
    blockLeft     := count - 2.U
    aLeft         := Mux(bipartite, split - 1.U, count - 2.U) // lastA
    headOffset    := io.headPad
    blockLeftIsM     := count === (m + 2).U
    aLeftAtLeast2m   := Mux(bipartite, jumps, count >= (2 * m + 2).U)
    blockEndNext     := count === 2.U // block 0 ends at once: left0 == 0
    hasNextBlockNext := Mux(bipartite, split > (m + (if (p.has(Fault.SkipSecondBlockAtMPlus2)) 1 else 0)).U,
      count >= (m + (if (p.has(Fault.SkipSecondBlockAtMPlus2)) 3 else 2)).U) // lastA >= m
    restartCapture()
  }

  // ---- the issue's fields, in control time (the lanes take them LaneLag cycles later) ----
  // Lane k holds object s+k-d, which exists while n - s > k - d, i.e.
  // laneTop >= k, a register. Lanes below d hold no object of the run. A
  // bipartite run also masks the lanes past the last A object (and, in the
  // lanes, those whose B object is in A).
  io.laneHasObjects := VecInit(Seq.tabulate(m)(k =>
    headOffset <= k.U &&
      (if (p.has(Fault.LaneMaskOneTooWide)) laneTop +& 1.U >= k.U else laneTop >= k.U) &&
      (aTop >= k.U || p.has(Fault.BipartiteALanesUnmasked).B))).asUInt
  // Lane k holds objects base + k - d and s + k - d: the beat's bases are
  // moved down by d (modulo 2^indexWidth; lanes below d never compare, so
  // no hit wraps), so that the mask needs no shift on its way out.
  private def movedDown(x: UInt): UInt =
    (if (p.has(Fault.ShortRunBasesNotMoved)) x else x - headOffset)(p.indexWidth - 1, 0)
  io.iBase := movedDown(base)
  io.jBase := movedDown(s)

  io.active  := active
  io.issuing := issuing
  io.issue   := issue
}
