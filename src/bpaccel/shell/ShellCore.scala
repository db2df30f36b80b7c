package bpaccel.shell

import chisel3._
import chisel3.util._

/** Everything of the shell on the core's clock: the input words, the
  * command control, the core's adapter and the reply packer.
  *
  * The control reads each packet's header word and runs one command at a
  * time: the next header is read only after the reply's trailer was handed
  * to the packer and the packet was read to its TLAST.
  *
  *  - Body: items go to the adapter as it asks for them. TLAST inside an
  *    item, or after an item that is not the last, is LENGTH_MISMATCH; so is
  *    padding that is not zero or not on the beat that holds the last item.
  *  - An error in an item's content, a LENGTH_MISMATCH or an abort cancel
  *    the adapter (its core restarts) and the rest of the packet is drained.
  *  - The trailer carries the first error of the command and the adapter's
  *    summary; it leaves once the summary is in and the input has been read
  *    to its TLAST or is known to be in error (an abort's trailer does not
  *    wait for a packet that may never end).
  */
class ShellCore(p: ShellParams) extends Module {
  val io = IO(new Bundle {
    val in    = Flipped(Decoupled(new InputBeat(p.streamBits)))
    val out   = Decoupled(new OutputBeat(p.streamBits))
    val abort = Input(Bool()) // a pulse: end the current command
  })
  val words   = Module(new InputWords(p))
  val adapter = Module(CoreAdapter(p))
  val packer  = Module(new ReplyPacker(p, adapter.recordWords))
  words.io.in <> io.in
  io.out <> packer.io.out
  packer.io.records <> adapter.io.records

  object State extends ChiselEnum { val Header, Body, Padding, Drain, Done = Value }
  val state   = RegInit(State.Header)
  val pending = RegInit(false.B) // a command's trailer has not yet gone to the packer
  val running = RegInit(false.B) // the adapter runs and owes its summary
  val opcode  = RegInit(0.U(8.W))
  val error   = RegInit(0.U(8.W))
  val detail  = RegInit(0.U(32.W))
  val summary = Reg(new CommandSummary)
  val summaryIn = RegInit(false.B)

  private val window = words.io.window
  adapter.io.window := window
  private def fail(code: UInt, where: UInt): Unit = when(error === 0.U) { error := code; detail := where }
  // An abort wins over the body's item in its cycle: nothing more is taken.
  val aborting = io.abort && pending

  val consume = WireDefault(0.U(log2Ceil(p.parserBufferWords + 1).W))
  words.io.consume := consume
  val start  = WireDefault(false.B)
  val take   = WireDefault(false.B)
  val cancel = WireDefault(false.B)
  val ended  = WireDefault(false.B)
  adapter.io.start := start
  adapter.io.take  := take
  adapter.io.ended := ended

  // The header: [7:0] opcode, [15:8] version, [31:16] zero.
  private val header = window.words(0)
  private val known  = header(15, 8) === Protocol.Version.U && header(31, 16) === 0.U
  when(state === State.Header && !pending && window.count =/= 0.U) {
    consume := 1.U
    pending := true.B
    opcode  := header(7, 0)
    error   := 0.U
    detail  := 0.U
    summaryIn := false.B
    when(known && header(7, 0) === adapter.opcode.code.U) {
      when(window.last(0)) { // the body is missing
        error := Protocol.LengthMismatch.code.U
        summary := 0.U.asTypeOf(summary)
        summaryIn := true.B
        state := State.Done
      }.otherwise {
        start   := true.B
        running := true.B
        state   := State.Body
      }
    }.otherwise {
      error := Protocol.BadCommand.code.U
      summary := 0.U.asTypeOf(summary)
      summaryIn := true.B
      state := Mux(window.last(0), State.Done, State.Drain)
    }
  }

  // The body, one item a cycle.
  private val need        = adapter.io.need
  private val inItem      = VecInit.tabulate(p.itemWords)(i => i.U < need && i.U < window.count)
  private val lastInItem  = window.last.zip(inItem).map { case (l, in) => l && in }
  private val whole       = window.count >= need
  private val endsAt      = PriorityEncoder(lastInItem)
  private val endsInside  = lastInItem.reduce(_ || _) && endsAt =/= need - 1.U
  private val endsWithIt  = whole && window.last(need - 1.U)
  when(state === State.Body && !aborting) {
    when(endsInside || endsWithIt && !adapter.io.last) { // TLAST before the body's end
      consume := endsAt + 1.U
      fail(Protocol.LengthMismatch.code.U, adapter.io.position)
      cancel := true.B
      ended  := true.B
      state  := State.Done
    }.elsewhen(whole && adapter.io.itemError.valid) {
      consume := need
      fail(adapter.io.itemError.bits.code, adapter.io.itemError.bits.detail)
      cancel := true.B
      state  := Mux(endsWithIt, State.Done, State.Drain)
    }.elsewhen(whole && adapter.io.ready) {
      consume := need
      take    := true.B
      when(adapter.io.last) { state := Mux(endsWithIt, State.Done, State.Padding) }
    }
  }

  // After the last item: the rest of its beat is zero and ends the packet
  // (a whole beat after it, when it ended a beat, is one too many).
  when(state === State.Padding && !aborting && window.count =/= 0.U) {
    consume := window.restOfBeat
    when(window.restZero && window.beatLast && window.restOfBeat =/= p.wordsPerBeat.U) {
      state := State.Done
    }.otherwise {
      fail(Protocol.LengthMismatch.code.U, adapter.io.position)
      state := Mux(window.beatLast, State.Done, State.Drain)
    }
  }
  when(state === State.Drain && window.count =/= 0.U) {
    consume := window.restOfBeat
    when(window.beatLast) { state := State.Done }
  }

  // An abort ends the command being read or answered; between commands it does nothing.
  when(aborting) {
    fail(Protocol.Aborted.code.U, 0.U)
    cancel := true.B
    when(state === State.Body || state === State.Padding) { state := State.Drain }
  }

  // The adapter's summary; a cancel only while it still owes one (never in the cycle it gives it).
  adapter.io.summary.ready := true.B
  adapter.io.cancel := cancel && running && !adapter.io.summary.valid
  when(adapter.io.summary.fire) {
    summary   := adapter.io.summary.bits
    summaryIn := true.B
    running   := false.B
    // The core's error names content before anything found after it (a summary after a cancel carries none).
    val coreError = adapter.io.summary.bits.error
    when(coreError.code =/= 0.U) { error := coreError.code; detail := coreError.detail }
  }

  // The trailer (docs/protocol.md).
  val resolved = state === State.Done || state === State.Drain
  packer.io.trailer.valid := pending && summaryIn && resolved
  private val s = summary
  private def split64(v: UInt): Seq[UInt] = Seq(v(31, 0), v(63, 32))
  packer.io.trailer.bits := VecInit(
    Seq(Cat(Protocol.TrailerMagic.U(8.W), opcode, error, 0.U(8.W)), detail, s.records, s.boxes) ++
      split64(s.intakeCycles + s.runCycles) ++ split64(s.stallCycles) ++ split64(s.issueCycles) ++
      split64(s.pairs) ++ split64(s.intakeCycles) ++ Seq(s.cells, 0.U(32.W))
  )
  when(packer.io.trailer.fire) { pending := false.B }
  when(state === State.Done && !pending) { state := State.Header }
}
