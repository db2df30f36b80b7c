package bpaccel.binning

import chisel3._
import chisel3.util._

/** The frame's phases, its header checks, its error and its summary.
  *
  * After a reset or an abort it clears every group's cell table (one row a
  * cycle, localCells cycles) before it takes a header. A header starts the
  * intake; header errors (COUNT_OVER_CAPACITY, BAD_GRID) only drain the
  * packet. The intake is over in the first cycle in which the last beat was
  * taken, the intake register is empty and every group's writer is idle;
  * then, without an error, the groups start (prefix in the next cycle) and
  * the frame is finished once every group is done and the output path is
  * empty; with an error, the tables are cleared again (localCells cycles).
  * The summary is valid from the next cycle until taken.
  */
class FrameControl(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val frame        = Flipped(Decoupled(new FrameHeader))
    val summary      = Decoupled(new FrameSummary(p))
    // to and from the intake
    val frameStart   = Output(Bool())
    val headerError  = Output(Bool())
    val intakeActive = Output(Bool())
    val n            = Output(UInt(32.W))
    val shift        = Output(UInt(p.shiftWidth.W))
    val dims         = Output(Vec(3, UInt(p.dimWidth.W)))
    val localDims    = Output(Vec(3, UInt((p.cellBits + 1).W)))
    val intakeError  = Flipped(Valid(new Bundle { val code = BinningError(); val detail = UInt(32.W) }))
    val lastTaken    = Input(Bool())
    val intakeHolding = Input(Bool())
    val received     = Input(UInt(32.W))
    // to and from the groups and the output path
    val groupsIdle   = Input(Bool()) // every writer idle
    val startGroups  = Output(Bool())
    val clear        = Valid(UInt(p.localCellBits.W))
    val groupsDone   = Input(Bool())
    val outputEmpty  = Input(Bool())
    val entries      = Input(UInt(32.W))
    val maxEntries   = Input(UInt(32.W))
    val issueCycles  = Input(UInt(p.counterWidth.W))
    val pairsOffered = Input(Bool())
    val pairsTaken   = Input(UInt(log2Ceil(p.pairsPerBeat + 1).W)) // pairs handed over in this cycle
  })
  object State extends ChiselEnum { val Clearing, Idle, Intake, Groups, ErrorClear, Summary = Value }
  val state = RegInit(State.Clearing)
  val row   = RegInit(0.U(p.localCellBits.W))
  val clearing = state === State.Clearing || state === State.ErrorClear
  io.clear.valid := clearing
  io.clear.bits  := row
  when(clearing) { row := row + 1.U }
  val lastRow = row === (p.localCells - 1).U

  // ---- header ----
  val n     = Reg(UInt(32.W))
  val shift = Reg(UInt(p.shiftWidth.W))
  val dims  = Reg(Vec(3, UInt(p.dimWidth.W)))
  val h = io.frame.bits
  val badGrid = h.shift > p.maxShift.U || h.dims.map(d => d === 0.U || d > (1 << p.cellBits).U).reduce(_ || _)
  val headerCode = Wire(BinningError())
  headerCode := MuxCase(BinningError.None, Seq(
    (h.n > p.boxCapacity.U) -> BinningError.CountOverCapacity,
    badGrid                 -> BinningError.BadGrid
  ))
  io.frame.ready  := state === State.Idle
  io.frameStart   := io.frame.fire
  io.headerError  := headerCode =/= BinningError.None
  io.intakeActive := state === State.Intake
  io.n     := n
  io.shift := shift
  io.dims  := dims
  // ceil(D / 2^a) as D >> a plus one when the dropped bits are not zero (no adder bit computed unused).
  io.localDims := VecInit((0 until 3).map { a =>
    val ga = p.groupBits(a)
    ((dims(a) >> ga) +& dims(a)(ga - 1, 0).orR).pad(p.cellBits + 1)
  })

  // ---- error: the first of the frame ----
  val error  = RegInit(BinningError.None)
  val detail = RegInit(0.U(32.W))
  when(io.intakeError.valid && error === BinningError.None) {
    error  := io.intakeError.bits.code
    detail := io.intakeError.bits.detail
  }

  // ---- counters ----
  val cycles       = RegInit(0.U(p.counterWidth.W))
  val intakeCycles = RegInit(0.U(p.counterWidth.W))
  val stallCycles  = RegInit(0.U(p.counterWidth.W))
  val records      = RegInit(0.U(32.W))
  val running = state === State.Intake || state === State.Groups || state === State.ErrorClear
  when(running) { cycles := cycles + 1.U }
  when(running && io.pairsOffered && io.pairsTaken === 0.U) { stallCycles := stallCycles + 1.U }
  records := records + io.pairsTaken

  // ---- phases ----
  val intakeOver = state === State.Intake && io.lastTaken && !io.intakeHolding && io.groupsIdle
  val failed     = error =/= BinningError.None || io.intakeError.valid
  io.startGroups := intakeOver && !failed
  val finished = (state === State.Groups && io.groupsDone && io.outputEmpty) || (state === State.ErrorClear && lastRow)
  val summary = Reg(new FrameSummary(p))
  switch(state) {
    is(State.Clearing) { when(lastRow) { state := State.Idle } }
    is(State.Idle) {
      when(io.frame.fire) {
        state  := State.Intake
        n      := h.n
        shift  := h.shift
        dims   := VecInit(h.dims.map(_(p.dimWidth - 1, 0)))
        error  := headerCode
        detail := 0.U
        cycles := 1.U
        stallCycles := 0.U
        records := 0.U
      }
    }
    is(State.Intake) {
      when(intakeOver) {
        intakeCycles := cycles + 1.U
        state := Mux(failed, State.ErrorClear, State.Groups)
        row   := 0.U
      }
    }
    is(State.Groups) {}
    is(State.ErrorClear) {}
    is(State.Summary) { when(io.summary.fire) { state := State.Idle } }
  }
  when(finished) {
    state := State.Summary
    summary.error   := error
    summary.detail  := detail
    summary.records := records
    summary.boxes   := io.received
    summary.entries := io.entries
    summary.maxGroupEntries := io.maxEntries
    summary.cycles       := cycles + 1.U
    summary.intakeCycles := Mux(error === BinningError.None, intakeCycles, 0.U)
    summary.issueCycles  := io.issueCycles
    summary.stallCycles  := stallCycles
  }
  io.summary.valid := state === State.Summary
  io.summary.bits  := summary
}
