package bpaccel

import chisel3.util.log2Ceil

/** How the coordinate memories are built (see [[RegisteredReadMemory]]).
  *
  *  - [[MemoryStyle.Inferred]]: a `SyncReadMem`, every output register in the
  *    fabric. Yosys folds the first register into the block RAM's synchronous
  *    read, but cannot use the DP16KD's own output register (REGMODE OUTREG).
  *  - [[MemoryStyle.Ecp5OutputRegister]]: each memory and the first of its
  *    output registers form one module, [[RegisteredReadMemory]]; the FPGA flow
  *    builds it from DP16KD with the output register on (scripts/fpga/ecp5). The
  *    same registers, the same cycles: simulation and proofs do not change.
  */
sealed abstract class MemoryStyle(val name: String) {
  /** The module of one coordinate memory in the emitted Verilog. */
  def moduleName(rows: Int, width: Int): String

  /** Cycles from a read's row to its data (see [[CoordinateMemory]]). */
  def readLatency: Int
}
object MemoryStyle {
  case object Inferred extends MemoryStyle("inferred") {
    def moduleName(rows: Int, width: Int): String = s"mem_${rows}x$width" // firtool's name for a SyncReadMem
    def readLatency = 1
  }
  case object Ecp5OutputRegister extends MemoryStyle("ecp5-outreg") {
    def moduleName(rows: Int, width: Int): String = s"${RegisteredReadMemory.namePrefix}${rows}x$width"
    def readLatency: Int = RegisteredReadMemory.readLatency
  }
  val all: Seq[MemoryStyle] = Seq(Inferred, Ecp5OutputRegister)
  def fromName(name: String): MemoryStyle =
    all.find(_.name == name).getOrElse(
      throw new IllegalArgumentException(
        s"memoryStyle must be one of ${all.map(_.name).mkString(", ")}, got memoryStyle = $name"
      )
    )
}

/** Every parameter of the generator, checked once here so that every module
  * can trust them.
  *
  * @param m                parallelism: lanes, i.e. pair tests per cycle (any m >= 1)
  * @param capacity         most objects one run can hold; for the seed a multiple of m
  * @param keyWidth         bits of one coordinate key (order-preserving image of a float32)
  * @param resultQueueDepth result beats buffered before the schedule must stall
  * @param memoryOutputStages registers after each memory's read data. FPGA synthesis folds
  *                         the first into the block RAM's synchronous read, so it takes
  *                         two for the logic to start from a fabric register (measured:
  *                         with one, the BRAM's clock-to-out fed the rotator directly)
  * @param debugPort        add a port that shows every lane's (i, j, valid) per cycle, for tests
  * @param arch             which architecture to build (see [[Arch]])
  * @param counterWidth     bits of each run counter (cycles, hits, ...); 64 cannot overflow
  *                         within any run this design can hold. The formal checks narrow
  *                         them: their runs are short and wide adders slow the solver.
  * @param batchCells       cell counts the batch front end queues (see [[BatchControl]])
  * @param faults           deliberate bugs for the formal checks' mutant tests (see [[Fault]]);
  *                         empty for every real build
  * @param memoryStyle      how the coordinate memories are built (see [[MemoryStyle]]);
  *                         never changes a cycle
  */
case class AccelParams(
  m: Int = 8,
  capacity: Int = Arch.Stream.defaultCapacity(8), // either architecture's default at m = 8
  keyWidth: Int = 32,
  resultQueueDepth: Int = 16,
  memoryOutputStages: Int = 2,
  debugPort: Boolean = false,
  arch: Arch = Arch.Stream,
  counterWidth: Int = 64,
  batchCells: Int = 64,
  faults: Set[Fault] = Set.empty,
  memoryStyle: MemoryStyle = MemoryStyle.Inferred
) {
  require(m >= 1, s"parallelism m must be at least 1, got m = $m")
  require(capacity >= 2, s"capacity must be at least 2 objects, got capacity = $capacity")
  private val capacityProblem = arch.capacityProblem(m, capacity)
  require(capacityProblem.isEmpty, capacityProblem.getOrElse(""))
  require(
    memoryOutputStages >= 0 && memoryOutputStages <= 4,
    s"memoryOutputStages must lie in 0..4, got $memoryOutputStages"
  )
  require(
    memoryStyle != MemoryStyle.Ecp5OutputRegister || memoryOutputStages >= 1,
    s"memoryStyle ${MemoryStyle.Ecp5OutputRegister.name} moves the first memory output register into the " +
      s"block RAM, so it needs memoryOutputStages >= 1, got $memoryOutputStages"
  )
  require(keyWidth >= 1 && keyWidth <= 64, s"keyWidth must lie in 1..64, got keyWidth = $keyWidth")
  require(counterWidth >= 1 && counterWidth <= 64, s"counterWidth must lie in 1..64, got counterWidth = $counterWidth")
  require(batchCells >= 1 && batchCells < (1 << 16), s"batchCells must lie in 1..65535, got batchCells = $batchCells")
  require(m < (1 << 16) && capacity.toLong < (1L << 32), s"m must fit 16 bits and capacity 32 bits, got m = $m, capacity = $capacity")

  /** Bits of a result beat's cell tag: the index of its cell within its batch. */
  val cellTagWidth: Int = log2Ceil(batchCells).max(1)

  /** Rows of each of the m striped memories of the seed architecture. */
  val depth: Int = (capacity / m).max(1)

  val overlapsLoads: Boolean = arch.overlapsLoads
  val bipartiteRuns: Boolean = arch.bipartiteRuns
  val headObjects: Int       = arch.headObjects(m)

  /** Bits of an object index 0 .. capacity-1. */
  val indexWidth: Int = log2Ceil(capacity).max(1)

  /** The coordinate memories (see [[Arch.memoryCount]]). */
  val memoryCount: Int = arch.memoryCount(this)
  val memoryRows: Int  = arch.memoryRows(this)
  val memoryWidth: Int = arch.memoryWidth(this)

  require(
    memoryStyle != MemoryStyle.Ecp5OutputRegister || memoryRows <= RegisteredReadMemory.maxEcp5Rows,
    s"memoryStyle ${MemoryStyle.Ecp5OutputRegister.name} builds each memory from DP16KD of at most " +
      s"${RegisteredReadMemory.maxEcp5Rows} rows (no cascade), got $memoryRows rows"
  )

  /** Bits of an object count 0 .. capacity. */
  val countWidth: Int = log2Ceil(capacity + 1)

  /** Bits of a memory row address 0 .. depth-1. */
  val rowWidth: Int = log2Ceil(depth).max(1)

  /** Bits of a B-port row register, which may point one row past the last (depth). */
  val bRowWidth: Int = log2Ceil(depth + 1)

  /** Bits of a lane number / rotation amount 0 .. m-1. */
  val laneWidth: Int = log2Ceil(m).max(1)

  /** Read events from a memory address to its data at the stream's window
    * entry: the memory's own read, the output registers and the read queue's
    * head register.
    */
  val readLatency: Int = 1 + memoryOutputStages + 1

  /** Cycles from an issue to its hit mask at the result queue. */
  val pipelineLatency: Int = arch.pipelineLatency(this)

  /** Cycles a run of n >= 2 objects takes after its issue cycles when the
    * consumer never stalls: the pipeline's latency plus the cycle that sees it
    * drained (the result queue passes beats through in the cycle they arrive).
    */
  val runOverheadCycles: Int = pipelineLatency + 1

  /** Cycles between the start and the first issue of any run of n >= 2 objects. */
  val startupLatency: Int = arch.startupLatency(this)

  def startupCycles(n: Long): Long = if (n < 2) 0 else startupLatency.toLong

  /** Every cycle of a run of n objects beyond issues and stalls. */
  def fixedCycles(n: Long): Long = if (n < 2) 0 else startupCycles(n) + runOverheadCycles

  require(
    resultQueueDepth >= pipelineLatency + 3,
    s"resultQueueDepth must be at least pipelineLatency + 3 = ${pipelineLatency + 3} " +
      s"so a consumer that is always ready never stalls the schedule, got $resultQueueDepth"
  )

  /** Whether the mutant tests asked for this deliberate bug. */
  def has(fault: Fault): Boolean = faults.contains(fault)
}

object AccelParams {
  /** Rows per seed memory when no capacity is given: one block RAM's worth. */
  val defaultRows: Int = 256
}
