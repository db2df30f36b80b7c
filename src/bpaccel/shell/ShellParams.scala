package bpaccel.shell

import scala.language.implicitConversions

import chisel3.util.{isPow2, log2Ceil}

import bpaccel.{AccelParams, Arch}
import bpaccel.binning.{BinningHeader, BinningParams}

/** The core behind the shell: a CELLS device (seed or stream) or the binning device.
  * Either core's parameters convert to it, so `ShellParams(AccelParams(...))`
  * and `ShellParams(BinningParams(...))` both read as they mean.
  */
sealed trait ShellCoreParams {
  def keyWidth: Int
  def indexWidth: Int
  def debugPort: Boolean
  /** The ARCH register's value. */
  def archId: Int
  /** The core's configuration string. */
  def fingerprint: String
}

object ShellCoreParams {
  case class Cells(p: AccelParams) extends ShellCoreParams {
    def keyWidth   = p.keyWidth
    def indexWidth = p.indexWidth
    def debugPort  = p.debugPort
    def archId     = p.arch.id
    def fingerprint = bpaccel.CHeader.fingerprint(p)
  }
  case class Binning(p: BinningParams) extends ShellCoreParams {
    def keyWidth   = p.keyWidth
    def indexWidth = p.indexWidth
    def debugPort  = p.debugPort
    def archId     = BinningHeader.archId
    def fingerprint = p.fingerprint
  }
  implicit def fromCells(p: AccelParams): ShellCoreParams     = Cells(p)
  implicit def fromBinning(p: BinningParams): ShellCoreParams = Binning(p)
}

/** Every parameter of the AXI shell (docs/integration.md), checked once here.
  *
  * @param core        the core the shell wraps: a CELLS device (seed or stream, AccelParams)
  *                    or the binning device (BinningParams)
  * @param streamBits  TDATA width of both AXI4-Stream ports: 64, 128, 256 or 512
  * @param dualClock   the core on its own clock (`core_clk`), with gray-code
  *                    asynchronous FIFOs to the bus clock; else one clock (`aclk`)
  * @param fifoDepth   beats each crossing FIFO holds (a power of two)
  */
case class ShellParams(
  core: ShellCoreParams = AccelParams(m = 8, capacity = 64, arch = Arch.Stream),
  streamBits: Int = 128,
  dualClock: Boolean = true,
  fifoDepth: Int = 16
) {
  require(Seq(64, 128, 256, 512).contains(streamBits), s"streamBits must be 64, 128, 256 or 512, got $streamBits")
  require(core.keyWidth <= 32, s"the stream carries keys of at most 32 bits, got keyWidth = ${core.keyWidth}")
  require(isPow2(fifoDepth) && fifoDepth >= 4, s"fifoDepth must be a power of two of at least 4, got $fifoDepth")
  require(!core.debugPort, "the shell wraps a core without its debug port")
  require(binning.forall(_.faults.isEmpty), "the shell wraps a binning core without deliberate faults")

  /** The CELLS core's parameters, if the shell wraps one. */
  def cellsCore: Option[AccelParams] = core match {
    case ShellCoreParams.Cells(c) => Some(c)
    case _                        => None
  }
  /** The binning core's parameters, if the shell wraps one. */
  def binning: Option[BinningParams] = core match {
    case ShellCoreParams.Binning(b) => Some(b)
    case _                          => None
  }
  /** The CELLS core's parameters, for the code that only a CELLS shell elaborates. */
  def cells: AccelParams = cellsCore.getOrElse(throw new IllegalStateException("the shell wraps the binning core, not a CELLS core"))

  /** 32-bit words a beat carries. */
  val wordsPerBeat: Int = streamBits / 32

  /** A key takes a 16-bit half-word when it fits, else a whole word. */
  val keySlotBits: Int = if (core.keyWidth <= 16) 16 else 32

  /** Words of one box on the stream: six keys. */
  val boxWords: Int = 6 * keySlotBits / 32

  /** Words of a pair's indices in a record: {j, i} in one word when indices fit 16 bits, else i then j. */
  val indexWords: Int = if (core.indexWidth <= 16) 1 else 2

  /** Mask words of a CELLS record: bit k of word w is lane 32 w + k (0 for FRAME). */
  val maskWords: Int = cellsCore.fold(0)(c => (c.m + 31) / 32)

  /** Words of one record: CELLS: indices, the cell's index in the command, the hit mask; FRAME: indices. */
  val recordWords: Int = if (binning.isDefined) indexWords else indexWords + 1 + maskWords

  /** FRAME's header after the opcode: n, the shift, the dimensions. */
  val frameHeaderWords: Int = 3

  /** The longest item a parser takes from the input in one cycle: CELLS: a box (a cell header is 2
    * words); FRAME: the core's intake of boxes (its header is 3 words).
    */
  val itemWords: Int = binning.fold(boxWords.max(2))(b => (b.intakeBoxes * boxWords).max(frameHeaderWords))

  /** Words the input parser buffers: enough that it takes one item a cycle while beats keep coming. */
  val parserBufferWords: Int = 1 << log2Ceil(wordsPerBeat + 2 * itemWords)

  /** Opcodes this device answers (Protocol.Opcode). */
  val opcodes: Seq[Protocol.Opcode] = Seq(if (binning.isDefined) Protocol.Frame else Protocol.Cells)

  /** The same configuration as one string, for the fingerprint register and the C header. */
  def fingerprint: String =
    s"${core.fingerprint},stream_bits=$streamBits,dual_clock=${if (dualClock) 1 else 0},fifo=$fifoDepth"
}
