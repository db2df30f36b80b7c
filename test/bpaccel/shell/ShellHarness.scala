package bpaccel.shell

import scala.collection.mutable
import scala.util.Random

import chisel3._
import chiseltest._
import org.scalatest.Assertions.fail

import bpaccel.Box
import bpaccel.binning.BinningParams

/** The binning shell the specs build: G = 8 groups of 2 lanes, 12-bit keys, 8 cells per axis,
  * 64 boxes a frame, 48 entries a group, 4 boxes a cycle in, 4 pairs a cycle out.
  */
object ShellConfigs {
  val binningG8 = BinningParams(groupBits = Seq(1, 1, 1), lanesPerGroup = 2, keyWidth = 12, cellBits = 3, boxCapacity = 64,
    groupCapacity = 48, intakeBoxes = 4, pairsPerBeat = 4)
}

/** A one-clock shell as ChiselTest drives it: `aclk` is the test's clock, `aresetn` its reset.
  *
  * The core side's reset is a register of the shell's, which Verilator starts at 0: at the first
  * clock edge (ChiselTest's reset cycle, whose assertions it does not count) the binning core is not
  * yet in reset, and its readers print "the reader's credits do not match", once per group.
  */
class ShellHarness(val p: ShellParams) extends Module {
  require(!p.dualClock, "the harness drives one clock")
  private val shell = Module(new BpaccelShell(p))
  val s_axis = IO(Flipped(new AxiStream(p.streamBits)))
  val m_axis = IO(new AxiStreamWithKeep(p.streamBits))
  val s_axil = IO(Flipped(new AxiLite(ShellRegisters(p).addressBits)))
  shell.aclk    := clock
  shell.aresetn := !reset.asBool
  shell.s_axis <> s_axis
  m_axis <> shell.m_axis
  shell.s_axil <> s_axil
}

/** A reply as the host reads it: the trailer at its end, records before it. */
case class ShellReply(words: Vector[Long]) {
  val trailer: Vector[Long] = words.takeRight(Protocol.TrailerWords)
  private def at(name: String): Long = trailer(Protocol.trailerWord(name))
  private def wide(name: String): Long = at(name) | trailer(Protocol.trailerWord(name) + 1) << 32
  def magic: Long   = at("HEADER") >> 24
  def opcode: Long  = at("HEADER") >> 16 & 0xff
  def error: Long   = at("HEADER") >> 8 & 0xff
  def detail: Long  = at("DETAIL")
  def records: Long = at("RECORDS")
  def boxes: Long   = at("BOXES")
  def cells: Long   = at("CELLS")
  def deviceCycles: Long = wide("DEVICE_CYCLES")
  def stallCycles: Long  = wide("STALL_CYCLES")
  def issueCycles: Long  = wide("ISSUE_CYCLES")
  def pairs: Long        = wide("PAIRS")
  def intakeCycles: Long = wide("INTAKE_CYCLES")
  def body: Vector[Long] = words.dropRight(Protocol.TrailerWords)

  /** FRAME records: {j [31:16], i [15:0]}, or i then j. */
  def framePairs(indexWords: Int): Vector[(Int, Int)] =
    body.take(records.toInt * indexWords).grouped(indexWords).map { r =>
      if (indexWords == 1) ((r(0) & 0xffff).toInt, (r(0) >> 16).toInt) else (r(0).toInt, r(1).toInt)
    }.toVector
}

/** The host's side of the streams and the register bus, one clock at a time. */
class ShellDriver(dut: ShellHarness, rng: Random) {
  private val p = dut.p
  private val k = p.wordsPerBeat
  dut.clock.setTimeout(0)
  dut.s_axis.tvalid.poke(false.B)
  dut.m_axis.tready.poke(false.B)
  Seq(dut.s_axil.awvalid, dut.s_axil.wvalid, dut.s_axil.arvalid).foreach(_.poke(false.B))
  dut.s_axil.bready.poke(true.B)
  dut.s_axil.rready.poke(true.B)
  dut.s_axil.wstrb.poke(0xf.U)

  /** A command's words padded with zeros to whole beats. */
  def beats(words: Seq[Long]): Seq[(BigInt, Boolean)] = {
    val padded = words ++ Seq.fill((k - words.length % k) % k)(0L)
    val grouped = padded.grouped(k).toSeq
    grouped.zipWithIndex.map { case (b, i) =>
      (b.zipWithIndex.map { case (w, j) => BigInt(w & 0xffffffffL) << (32 * j) }.sum, i == grouped.length - 1)
    }
  }

  /** Cycles of the last exchange: from its first cycle to the one that took its last reply's TLAST. */
  var exchangeCycles: Long = 0

  /** Sends the commands back to back and returns their replies, in order.
    *
    * @param inGap     probability that the input offers no beat in a cycle
    * @param outStall  probability that the output is not ready in a cycle
    * @param hold      (beat, cycle): the input stops before that beat (counted over all commands) until that cycle
    * @param abortAt   the cycle in which CONTROL.ABORT is written
    */
  def exchange(commands: Seq[Seq[Long]], inGap: Double = 0, outStall: Double = 0, hold: Option[(Int, Long)] = None,
               abortAt: Option[Long] = None, maxCycles: Long = 200000): Seq[ShellReply] = {
    val toSend  = mutable.Queue.from(commands.flatMap(beats))
    val replies = Vector.newBuilder[ShellReply]
    var current = Vector.newBuilder[Long]
    var got = 0
    var sent = 0
    var t = 0L
    var writing = false
    while (got < commands.length) {
      if (t > maxCycles) fail(s"no reply to command $got within $maxCycles cycles")
      val held  = hold.exists { case (beat, until) => sent == beat && t < until }
      val offer = toSend.nonEmpty && !held && rng.nextDouble() >= inGap
      dut.s_axis.tvalid.poke(offer.B)
      if (offer) {
        dut.s_axis.tdata.poke(toSend.head._1.U(p.streamBits.W))
        dut.s_axis.tlast.poke(toSend.head._2.B)
      }
      val ready = rng.nextDouble() >= outStall
      dut.m_axis.tready.poke(ready.B)
      if (abortAt.contains(t)) {
        writing = true
        dut.s_axil.awaddr.poke(ShellRegisters.ControlOffset.U)
        dut.s_axil.wdata.poke(1.U) // CONTROL.ABORT
      }
      dut.s_axil.awvalid.poke(writing.B)
      dut.s_axil.wvalid.poke(writing.B)
      if (writing && dut.s_axil.awready.peek().litToBoolean) writing = false // the bank takes address and data together
      if (offer && dut.s_axis.tready.peek().litToBoolean) { toSend.dequeue(); sent += 1 }
      if (ready && dut.m_axis.tvalid.peek().litToBoolean) {
        val data = dut.m_axis.tdata.peek().litValue
        current ++= (0 until k).map(j => ((data >> (32 * j)) & 0xffffffffL).toLong)
        if (dut.m_axis.tlast.peek().litToBoolean) {
          replies += ShellReply(current.result())
          current = Vector.newBuilder[Long]
          got += 1
          exchangeCycles = t + 1
        }
      }
      dut.clock.step()
      t += 1
    }
    dut.s_axis.tvalid.poke(false.B)
    dut.m_axis.tready.poke(false.B)
    replies.result()
  }

  /** One AXI4-Lite read. */
  def read(offset: Int): Long = {
    dut.s_axil.araddr.poke(offset.U)
    dut.s_axil.arvalid.poke(true.B)
    var n = 0
    while (!dut.s_axil.arready.peek().litToBoolean) { dut.clock.step(); n += 1; if (n > 100) fail("arready stayed low") }
    dut.clock.step()
    dut.s_axil.arvalid.poke(false.B)
    while (!dut.s_axil.rvalid.peek().litToBoolean) { dut.clock.step(); n += 1; if (n > 100) fail("rvalid stayed low") }
    val v = dut.s_axil.rdata.peek().litValue.toLong
    dut.clock.step()
    v
  }
}

/** FRAME packets as the host writes them (docs/protocol.md). */
object FrameWords {
  def header(opcode: Int): Long = opcode | Protocol.Version << 8

  /** A box's six keys in 16-bit half-words (3 words) or words (6). */
  def box(p: ShellParams, b: Box): Seq[Long] = {
    val keys = (b.min ++ b.max).map(_.toLong)
    if (p.boxWords == 6) keys else (0 until 3).map(i => keys(2 * i) | keys(2 * i + 1) << 16)
  }

  /** A FRAME command: header, n, shift, dims, then the boxes (n defaults to their number). */
  def frame(p: ShellParams, boxes: Seq[Box], shift: Long, dims: Seq[Int], n: Option[Long] = None, dimsHigh: Long = 0): Seq[Long] =
    Seq(header(Protocol.Frame.code), n.getOrElse(boxes.length.toLong), shift,
      dims(0) | dims(1) << 8 | dims(2) << 16 | dimsHigh << 24) ++ boxes.flatMap(box(p, _))
}
