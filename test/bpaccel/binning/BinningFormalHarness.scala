package bpaccel.binning

import chisel3._
import chisel3.util._

import bpaccel.Aabb

/** A group of properties [[BinningFormalHarness]] asserts, each with its own messages. */
sealed abstract class BinProperty(val name: String)
object BinProperty {
  /** Each pair a group hands out is two entries of one cell that overlap with the exactly-once rule, and none comes twice. */
  case object Pairs extends BinProperty("pairs")
  /** Once a group has nothing left, every pair its cells owe came out. */
  case object Complete extends BinProperty("complete")
  /** A frame's summary names its first error (code and box) as the protocol defines it; a frame with an error sends no pair. */
  case object Errors extends BinProperty("errors")
  /** Nothing is offered outside a frame, the summary never beside a pair, and it counts the boxes taken and the pairs sent. */
  case object Summary extends BinProperty("summary")

  /** The output path hands out every pair that entered it once, each group's in order, whatever the consumer does. */
  case object Delivery extends BinProperty("delivery")

  val all: Seq[BinProperty] = Seq(Pairs, Complete, Errors, Summary, Delivery)
}

/** Formal-only wrapper: the core with every input free (headers, boxes, beat
  * timing, `last`, the consumer's ready, abort) and monitors that see only
  * its ports. They keep their own count of the frame (header, boxes in
  * stream order, entries per group) and decide from it, in plain terms,
  * which error comes first; they read nothing inside the core. (The pairs a
  * frame reports come ~30 cycles after its header at the least, beyond what
  * the solver reaches for the whole core: [[EngineFormalHarness]] proves them
  * for a group's schedule, the cycle-exact simulation for the whole core.)
  */
class BinningFormalHarness(p: BinningParams, properties: Set[BinProperty] = Set(BinProperty.Errors, BinProperty.Summary))
    extends Module {
  require(p.intakeBoxes == 1, "the monitors take one box a beat")
  val io = IO(new BinningPorts(p))
  val dut = Module(new BinningCore(p))
  dut.io.frame <> io.frame
  dut.io.boxes <> io.boxes
  dut.io.abort := io.abort
  io.pairs <> dut.io.pairs
  io.summary <> dut.io.summary

  private def check(property: BinProperty, cond: Bool, what: String): Unit =
    if (properties.contains(property)) assert(cond, s"[${property.name}] $what")

  private val cap = p.boxCapacity
  private val countBits = 32

  // ---- the frame as the monitors see it ----
  val inFrame  = RegInit(false.B) // a header was taken and its summary not yet
  val n        = Reg(UInt(countBits.W))
  val shift    = Reg(UInt(log2Ceil(p.keyWidth + 1).W)) // only read in frames whose shift is legal
  val dims     = Reg(Vec(3, UInt(8.W)))
  val received = RegInit(0.U(countBits.W))
  val boxes    = Reg(Vec(cap, new Aabb(p.keyWidth)))
  val error    = RegInit(BinningError.None)
  val detail   = Reg(UInt(32.W))
  val groupFill = Reg(Vec(p.groups, UInt(log2Ceil(cap + 2).W)))

  val h = io.frame.bits
  val headerCode = Wire(BinningError())
  headerCode := MuxCase(BinningError.None, Seq(
    (h.n > cap.U) -> BinningError.CountOverCapacity,
    (h.shift > p.maxShift.U || h.dims.map(d => d === 0.U || d > (1 << p.cellBits).U).reduce(_ || _)) -> BinningError.BadGrid
  ))
  when(io.frame.fire) {
    inFrame  := true.B
    n        := h.n
    shift    := Mux(h.shift > p.keyWidth.U, p.keyWidth.U, h.shift)
    dims     := h.dims
    received := 0.U
    error    := headerCode
    detail   := 0.U
    groupFill.foreach(_ := 0.U)
  }

  // The groups a box puts an entry into: per axis the classes (cell mod 2^a) of its first and last cell.
  private def cellOf(key: UInt): UInt = key >> shift
  private def groupsOf(b: Aabb): Seq[Bool] = Seq.tabulate(p.groups) { gr =>
    (0 until 3).map { a =>
      val cls  = ((gr >> p.groupBits.take(a).sum) & ((1 << p.groupBits(a)) - 1)).U
      val mask = ((1 << p.groupBits(a)) - 1).U
      (cellOf(b.min(a)) & mask) === cls || (cellOf(b.max(a)) & mask) === cls
    }.reduce(_ && _)
  }
  val box  = io.boxes.bits.boxes(0)
  val takes = io.boxes.fire && box.valid
  when(takes) {
    val b = box.bits
    when(received < cap.U) { boxes(received(log2Ceil(cap) - 1, 0)) := b }
    received := received + 1.U
    val member = groupsOf(b)
    val code = MuxCase(BinningError.None, Seq(
      (received >= n) -> BinningError.LengthMismatch,
      (0 until 3).map(a => b.min(a) > b.max(a)).reduce(_ || _) -> BinningError.BoxInverted,
      (0 until 3).map(a => cellOf(b.max(a)) >= dims(a)).reduce(_ || _) -> BinningError.KeyOutOfGrid,
      (0 until 3).map(a => cellOf(b.max(a)) - cellOf(b.min(a)) > 1.U).reduce(_ || _) -> BinningError.BoxSpansCells,
      member.zip(groupFill).map { case (m, f) => m && f >= p.groupCapacity.U }.reduce(_ || _) -> BinningError.GroupOverflow
    ))
    when(error === BinningError.None) {
      error  := code
      detail := received
      when(code === BinningError.None) { for ((m, f) <- member.zip(groupFill)) when(m) { f := f + 1.U } }
    }
  }
  // The packet ends before n boxes: LENGTH_MISMATCH naming the boxes received, unless a box erred first.
  val lastNow  = io.boxes.fire && io.boxes.bits.last
  val short    = received + takes.asUInt < n
  val lengthShort = RegInit(false.B)
  when(io.frame.fire) { lengthShort := false.B }
  when(lastNow && short) { lengthShort := true.B }
  // The error the frame ends with: the first box error, else the packet's end before n boxes.
  val expectedError  = Mux(error === BinningError.None && lengthShort, BinningError.LengthMismatch, error)
  val expectedDetail = Mux(error === BinningError.None && lengthShort, received, detail)

  // ---- pairs sent, counted for the summary ----
  val sentCount = RegInit(0.U(32.W))
  when(io.frame.fire) { sentCount := 0.U }.elsewhen(io.pairs.fire) { sentCount := sentCount + PopCount(io.pairs.bits.pairs.map(_.valid)) }

  // ---- summary and errors ----
  val summed = io.summary.valid
  val s = io.summary.bits
  check(BinProperty.Summary, !(io.pairs.valid || io.summary.valid) || inFrame, "the core offers something outside a frame")
  check(BinProperty.Summary, !(io.pairs.valid && io.summary.valid), "the summary is offered while a pair is")
  check(BinProperty.Summary, !summed || s.records === sentCount, "the summary's record count is not the pairs sent")
  check(BinProperty.Summary, !summed || s.boxes === received, "the summary's box count is not the boxes taken")
  check(BinProperty.Errors, !summed || (s.error === expectedError && s.detail === expectedDetail),
    "the summary's error is not the frame's first")
  check(BinProperty.Errors, !(io.pairs.valid && inFrame && error =/= BinningError.None), "a frame with an error offers a pair")
  when(io.summary.fire) { inFrame := false.B }
  when(io.abort) { inFrame := false.B }
}
