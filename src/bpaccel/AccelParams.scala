package bpaccel

import chisel3.util.log2Ceil

/** The two architectures the generator builds; both have the same ports,
  * result beats and schedule (which pairs meet in which lane, in which order).
  *
  *  - [[Arch.Seed]]: the published design: 6m striped dual-port memories, an
  *    A/B address sequencer and a rotator.
  *  - [[Arch.Stream]]: one memory read per cycle feeds an m-deep shift register
  *    (the B window); A blocks sit in registers, the next one captured from
  *    the window as it passes. No rotator, memory independent of m.
  */
sealed abstract class Arch(val name: String, val id: Int)
object Arch {
  case object Seed   extends Arch("seed", 0)
  case object Stream extends Arch("stream", 1)
  val all: Seq[Arch] = Seq(Seed, Stream)
  def fromName(name: String): Arch =
    all.find(_.name == name).getOrElse(
      throw new IllegalArgumentException(s"arch must be one of ${all.map(_.name).mkString(", ")}, got arch = $name")
    )
}

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
sealed abstract class MemoryStyle(val name: String)
object MemoryStyle {
  case object Inferred           extends MemoryStyle("inferred")
  case object Ecp5OutputRegister extends MemoryStyle("ecp5-outreg")
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
  capacity: Int = AccelParams.defaultCapacity(8),
  keyWidth: Int = 32,
  resultQueueDepth: Int = 16,
  memoryOutputStages: Int = 2,
  debugPort: Boolean = false,
  arch: Arch = Arch.Seed,
  counterWidth: Int = 64,
  batchCells: Int = 64,
  faults: Set[Fault] = Set.empty,
  memoryStyle: MemoryStyle = MemoryStyle.Inferred
) {
  require(m >= 1, s"parallelism m must be at least 1, got m = $m")
  require(capacity >= 2, s"capacity must be at least 2 objects, got capacity = $capacity")
  require(
    arch != Arch.Seed || capacity % m == 0,
    s"capacity must be a multiple of m so the objects stripe evenly: capacity = $capacity, m = $m"
  )
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

  /** Whether a batch loads its next cell while the current one runs (see
    * [[BatchControl]]). The stream's memory then holds two banks of
    * `capacity` rows, one written while the other is read. The seed keeps
    * one: its memories already cost 6m block RAMs, the budget that caps its m.
    */
  val overlapsLoads: Boolean = arch == Arch.Stream

  /** Whether runs may be bipartite (a split in [[RunRequest]]): the stream's
    * reader jumps over the objects of A a block does not test; the seed's
    * schedule has no such jump, and refuses a split with an error.
    */
  val bipartiteRuns: Boolean = arch == Arch.Stream

  /** Objects 0 .. headObjects-1 of a run start it from registers: the seed's
    * block-0 A objects (m), the stream's head registers (m + 1: block 0's A
    * objects and its window).
    */
  val headObjects: Int = if (arch == Arch.Stream) m + 1 else m

  /** Bits of an object index 0 .. capacity-1. */
  val indexWidth: Int = log2Ceil(capacity).max(1)

  /** Rows of each coordinate memory: the seed's striped ones, or the stream's
    * single one, two banks of 2^indexWidth rows (a row is the bank bit over the index).
    */
  val memoryRows: Int = if (arch == Arch.Stream) 2 << indexWidth else depth

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

  /** Cycles from an issue to its hit mask at the result queue. Seed: memory
    * read, memory output registers, rotator register, comparator register, AND
    * register. Stream: the operands are already registers; the lanes' lag
    * (they act StreamEngine.LaneLag cycles after the control, see its
    * replicatedEnable), comparator register, AND register.
    */
  val pipelineLatency: Int = arch match {
    case Arch.Seed   => 1 + memoryOutputStages + 3
    case Arch.Stream => StreamEngine.LaneLag + 2
  }

  /** Cycles a run of n >= 2 objects takes after its issue cycles when the
    * consumer never stalls: the pipeline's latency plus the cycle that sees it
    * drained (the result queue passes beats through in the cycle they arrive).
    */
  val runOverheadCycles: Int = pipelineLatency + 1

  /** Cycles between the start and the first issue of a run of n >= 2
    * objects. Stream: the first readLatency reads travel to the window's
    * entry; the window and block 0's A objects are copied from the head
    * registers meanwhile.
    */
  def startupCycles(n: Long): Long = arch match {
    case Arch.Seed                => 0
    case Arch.Stream if n < 2     => 0
    case Arch.Stream              => readLatency.toLong
  }

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
  /** Rows per memory when no capacity is given: one block RAM's worth. */
  val defaultRows: Int = 256

  def defaultCapacity(m: Int): Int = defaultRows * m
}
