package bpaccel.shell

import chisel3.util.{isPow2, log2Ceil}

import bpaccel.{AccelParams, Arch}

/** Every parameter of the AXI shell (docs/integration.md), checked once here.
  *
  * @param core        the core the shell wraps (a CELLS device: seed or stream)
  * @param streamBits  TDATA width of both AXI4-Stream ports: 64, 128, 256 or 512
  * @param dualClock   the core on its own clock (`core_clk`), with gray-code
  *                    asynchronous FIFOs to the bus clock; else one clock (`aclk`)
  * @param fifoDepth   beats each crossing FIFO holds (a power of two)
  */
case class ShellParams(
  core: AccelParams = AccelParams(m = 8, capacity = 64, arch = Arch.Stream),
  streamBits: Int = 128,
  dualClock: Boolean = true,
  fifoDepth: Int = 16
) {
  require(Seq(64, 128, 256, 512).contains(streamBits), s"streamBits must be 64, 128, 256 or 512, got $streamBits")
  require(core.keyWidth <= 32, s"the stream carries keys of at most 32 bits, got keyWidth = ${core.keyWidth}")
  require(isPow2(fifoDepth) && fifoDepth >= 4, s"fifoDepth must be a power of two of at least 4, got $fifoDepth")
  require(!core.debugPort, "the shell wraps a core without its debug port")

  /** 32-bit words a beat carries. */
  val wordsPerBeat: Int = streamBits / 32

  /** A key takes a 16-bit half-word when it fits, else a whole word. */
  val keySlotBits: Int = if (core.keyWidth <= 16) 16 else 32

  /** Words of one box on the stream: six keys. */
  val boxWords: Int = 6 * keySlotBits / 32

  /** Words of a pair's indices in a record: {j, i} in one word when indices fit 16 bits, else i then j. */
  val indexWords: Int = if (core.indexWidth <= 16) 1 else 2

  /** Mask words of a CELLS record: bit k of word w is lane 32 w + k. */
  val maskWords: Int = (core.m + 31) / 32

  /** Words of a CELLS record: indices, the cell's index in the command, the hit mask. */
  val recordWords: Int = indexWords + 1 + maskWords

  /** The longest item a parser takes from the input in one cycle (a box; a cell header is 2 words). */
  val itemWords: Int = boxWords.max(2)

  /** Words the input parser buffers: enough that it takes one item a cycle while beats keep coming. */
  val parserBufferWords: Int = 1 << log2Ceil(wordsPerBeat + 2 * itemWords)

  /** Opcodes this device answers (Protocol.Opcode). */
  val opcodes: Seq[Protocol.Opcode] = Seq(Protocol.Cells)

  /** The same configuration as one string, for the fingerprint register and the C header. */
  def fingerprint: String =
    s"${bpaccel.CHeader.fingerprint(core)},stream_bits=$streamBits,dual_clock=${if (dualClock) 1 else 0},fifo=$fifoDepth"
}
