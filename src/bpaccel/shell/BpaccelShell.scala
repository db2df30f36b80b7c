package bpaccel.shell

import chisel3._
import chisel3.util._

/** The core in an AXI shell (docs/integration.md): AXI4-Stream in and out,
  * an AXI4-Lite register bank (ShellRegisters), an interrupt line.
  *
  * Clocks and resets: the bus side runs on `aclk` with the AXI reset
  * `aresetn` (active low, synchronous). With `dualClock` the core side runs
  * on `core_clk`, and its reset comes from the bus side's datapath reset
  * through a synchronizer (asserted at once, released on `core_clk`); the
  * stream FIFOs are gray-code asynchronous FIFOs. The input stream opens
  * (STATUS.READY) only once the core side has left reset. A soft reset holds
  * the bus side's datapath in reset until the core side is seen in reset,
  * then releases both; the register bank keeps its state.
  *
  * Every output port is a flip-flop or storage read behind flip-flops; no
  * input port reaches an output port through logic (checked by
  * test/bpaccel/shell/ShellSpec on every configuration it emits).
  */
class BpaccelShell(val p: ShellParams) extends RawModule {
  override def desiredName = "BpaccelShell"
  private val map = ShellRegisters(p)
  val aclk     = IO(Input(Clock()))
  val aresetn  = IO(Input(Bool()))
  val core_clk = if (p.dualClock) Some(IO(Input(Clock()))) else None
  val s_axis   = IO(Flipped(new AxiStream(p.streamBits)))
  val m_axis   = IO(new AxiStreamWithKeep(p.streamBits))
  val s_axil   = IO(Flipped(new AxiLite(map.addressBits)))
  val irq      = IO(Output(Bool()))

  private val hardReset = !aresetn
  private val coreClock = core_clk.getOrElse(aclk)

  // Bus side: the register bank (reset by aresetn only) and the datapath reset.
  val bank = withClockAndReset(aclk, hardReset) { Module(new AxiLiteRegisterBank(map)) }
  bank.io.axil <> s_axil
  private val hw = bank.io.hw
  private val softRequest = withClockAndReset(aclk, hardReset) { RegInit(false.B) }
  private val busReset    = withClockAndReset(aclk, hardReset) { RegNext(hardReset || softRequest, true.B) }
  // The same, as a register of its own that only resets the core side (asynchronously).
  private val coreResetRequest = withClockAndReset(aclk, hardReset) { RegNext(hardReset || softRequest, true.B) }

  // Core side: its reset, and whether it is out of reset (seen from the bus side as coreAlive).
  private val (coreReset, coreAlive) =
    if (p.dualClock) {
      val released = withClockAndReset(coreClock, coreResetRequest.asAsyncReset) {
        // A reset synchronizer: asserted at once (asynchronously), released on core_clk.
        val sync0 = RegInit(true.B).suggestName("coreReset_sync0")
        val sync1 = RegInit(true.B).suggestName("coreReset_sync1")
        sync0 := false.B
        sync1 := sync0
        val alive = RegInit(false.B).suggestName("coreAlive")
        alive := !sync1
        (sync1, alive)
      }
      // Its synchronizer keeps its state through a soft reset, which waits to see the core side fall.
      (released._1, withClockAndReset(aclk, hardReset) { ShellSync(released._2, "coreAlive") })
    } else (busReset, withClockAndReset(aclk, busReset) { RegNext(true.B, false.B) })

  withClockAndReset(aclk, hardReset) {
    when(hw("CONTROL_SOFT_RESET")(0)) { softRequest := true.B }
    // Released once the core side was seen in reset (at once with one clock).
    when(softRequest && busReset && !coreAlive) { softRequest := false.B }
  }

  // The streams' FIFOs.
  private val inBeat  = new InputBeat(p.streamBits)
  private val outBeat = new OutputBeat(p.streamBits)
  val (inFifoEnq, inFifoDeq, outFifoEnq, outFifoDeq) =
    if (p.dualClock) {
      val in  = Module(new AsyncFifo(inBeat, p.fifoDepth))
      val out = Module(new AsyncFifo(outBeat, p.fifoDepth))
      in.io.enqClock := aclk; in.io.enqReset := busReset; in.io.deqClock := coreClock; in.io.deqReset := coreReset
      out.io.enqClock := coreClock; out.io.enqReset := coreReset; out.io.deqClock := aclk; out.io.deqReset := busReset
      (in.io.enq, in.io.deq, out.io.enq, out.io.deq)
    } else {
      val (in, out) = withClockAndReset(aclk, busReset) { (Module(new Queue(inBeat, p.fifoDepth)), Module(new Queue(outBeat, p.fifoDepth))) }
      (in.io.enq, in.io.deq, out.io.enq, out.io.deq)
    }

  val core = withClockAndReset(coreClock, coreReset) { Module(new ShellCore(p)) }
  core.io.in <> inFifoDeq
  outFifoEnq <> core.io.out

  withClockAndReset(aclk, busReset) {
    val open = RegNext(coreAlive, false.B) // the input opens once the core side is out of reset
    inFifoEnq.valid     := s_axis.tvalid && open
    inFifoEnq.bits.data := s_axis.tdata
    inFifoEnq.bits.last := s_axis.tlast
    s_axis.tready       := inFifoEnq.ready && open
    m_axis.tvalid       := outFifoDeq.valid
    m_axis.tdata        := outFifoDeq.bits.data
    m_axis.tlast        := outFifoDeq.bits.last
    m_axis.tkeep        := Fill(p.streamBits / 8, 1.U(1.W))
    outFifoDeq.ready    := m_axis.tready

    // The abort crosses as a request held until the core side acknowledges it.
    val abortRequest = RegInit(false.B)
    val abortSeen = if (p.dualClock) {
      val ack = withClockAndReset(coreClock, coreReset) {
        val request = ShellSync(abortRequest, "abortRequest")
        val acked   = RegNext(request, false.B)
        core.io.abort := request && !acked
        acked
      }
      ShellSync(ack, "abortAck")
    } else {
      core.io.abort := abortRequest
      abortRequest
    }
    when(hw("CONTROL_ABORT")(0) && open) { abortRequest := true.B }
    when(abortSeen) { abortRequest := false.B }

    // What the register bank shows, from the streams as they pass.
    val inPacket  = RegInit(false.B)
    val replyOpen = RegInit(false.B)
    val inFire    = s_axis.tvalid && s_axis.tready
    val outFire   = m_axis.tvalid && m_axis.tready
    when(inFire) { inPacket := !s_axis.tlast }
    when(outFire) { replyOpen := !m_axis.tlast }
    val trailerWords = Reg(Vec(Protocol.TrailerWords, UInt(32.W)))
    val trailerBeat  = RegInit(0.U(log2Ceil(Protocol.TrailerWords / p.wordsPerBeat + 1).W))
    when(outFire && outFifoDeq.bits.trailer) {
      for (b <- 0 until Protocol.TrailerWords / p.wordsPerBeat; i <- 0 until p.wordsPerBeat)
        when(trailerBeat === b.U) { trailerWords(b * p.wordsPerBeat + i) := m_axis.tdata(32 * i + 31, 32 * i) }
      trailerBeat := Mux(m_axis.tlast, 0.U, trailerBeat + 1.U)
    }
    val delivered   = RegNext(outFire && outFifoDeq.bits.trailer && m_axis.tlast, false.B) // trailerWords complete
    val outstanding = RegInit(0.U(16.W)) // packets begun whose reply has not left
    outstanding := outstanding + (inFire && !inPacket).asUInt - delivered.asUInt
    val busy = outstanding =/= 0.U

    def word(name: String, offset: Int = 0): UInt = trailerWords(Protocol.trailerWord(name) + offset)
    def word64(name: String): UInt = Cat(word(name, 1), word(name))
    val errorCode  = word("HEADER")(15, 8)
    val lastReply  = RegInit(0.U(32.W))
    val lastDetail = RegInit(0.U(32.W))
    when(delivered) { lastReply := word("HEADER"); lastDetail := word("DETAIL") }
    def counter(add: UInt): UInt = { val c = RegInit(0.U(64.W)); c := c + add; c }
    def onDelivery(v: UInt): UInt = Mux(delivered, v, 0.U)
    val counters = Map(
      "REPLIES" -> counter(delivered.asUInt),
      "ERRORS" -> counter((delivered && errorCode =/= 0.U).asUInt),
      "RECORDS" -> counter(onDelivery(word("RECORDS"))),
      "BOXES" -> counter(onDelivery(word("BOXES"))),
      "DEVICE_CYCLES" -> counter(onDelivery(word64("DEVICE_CYCLES"))),
      "INTAKE_CYCLES" -> counter(onDelivery(word64("INTAKE_CYCLES"))),
      "ISSUE_CYCLES" -> counter(onDelivery(word64("ISSUE_CYCLES"))),
      "STALL_CYCLES" -> counter(onDelivery(word64("STALL_CYCLES"))),
      "PAIRS" -> counter(onDelivery(word64("PAIRS"))),
      "BUSY_CYCLES" -> counter(busy.asUInt)
    )
    for ((name, _) <- ShellRegisters.counterNames) hw(name) := counters(name)

    // Low from the cycle after a SOFT_RESET write, so a STATUS read after its response sees the reset.
    hw("STATUS_READY")      := open && !softRequest && !hw("CONTROL_SOFT_RESET")(0)
    hw("STATUS_BUSY")       := busy
    hw("STATUS_IN_PACKET")  := inPacket
    hw("STATUS_REPLY_OPEN") := replyOpen
    hw("STATUS_ABORTING")   := abortRequest || (if (p.dualClock) abortSeen else false.B)
    hw("STATUS_RESETTING")  := softRequest
    hw("LAST_REPLY_FLAGS")  := lastReply(7, 0)
    hw("LAST_REPLY_ERROR")  := lastReply(15, 8)
    hw("LAST_REPLY_OPCODE") := lastReply(23, 16)
    hw("LAST_REPLY_MAGIC")  := lastReply(31, 24)
    hw("LAST_DETAIL_VALUE") := lastDetail
    hw("IRQ_STATUS_REPLY_set") := delivered
    hw("IRQ_STATUS_ERROR_set") := delivered && errorCode =/= 0.U
  }

  irq := withClockAndReset(aclk, hardReset) {
    RegNext((hw("IRQ_STATUS_REPLY") & hw("IRQ_ENABLE_REPLY") | hw("IRQ_STATUS_ERROR") & hw("IRQ_ENABLE_ERROR")).asBool, false.B)
  }
}

/** Two flip-flops that bring a level into the current clock domain (`<name>_sync0`, `<name>_sync1`). */
object ShellSync {
  def apply(level: Bool, name: String): Bool = {
    val s0 = RegNext(level, false.B).suggestName(s"${name}_sync0")
    RegNext(s0, false.B).suggestName(s"${name}_sync1")
  }
}
