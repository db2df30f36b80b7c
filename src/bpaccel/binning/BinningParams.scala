package bpaccel.binning

import chisel3.util.log2Ceil

import bpaccel.MemoryStyle

/** The frame errors of the binning device, with their codes: the same codes
  * in the core's summary, the C header, the JSON parameter file and the
  * reply trailer. The core raises the codes up to [[BoxInverted]]; the
  * stream shell raises [[KeyTooWide]] and [[BadCommand]], which it detects
  * while unpacking packets (one numbering for the whole protocol).
  */
object BinningErrorCode {
  val None              = 0 // the frame is fine
  val CountOverCapacity = 1 // the header's n is above the box capacity
  val KeyOutOfGrid      = 2 // a key's cell (key >> shift) is not below the grid's cells on its axis
  val BoxSpansCells     = 3 // a box covers more than two cells on an axis
  val GroupOverflow     = 4 // a lane group's entry memory is full
  val LengthMismatch    = 5 // the packet ended before n boxes, or a box came after the n-th
  val BadGrid           = 6 // the header's shift is above localBits, or a grid dimension is 0 or above 2^cellBits
  val BoxInverted       = 7 // a box's min key is above its max key on an axis
  val KeyTooWide        = 8 // (shell) a key's unused high bits on the stream are not zero
  val BadCommand        = 9 // (shell) an opcode or version the device does not answer

  val names: Seq[(String, Int)] = Seq(
    "NONE" -> None,
    "COUNT_OVER_CAPACITY" -> CountOverCapacity,
    "KEY_OUT_OF_GRID" -> KeyOutOfGrid,
    "BOX_SPANS_CELLS" -> BoxSpansCells,
    "GROUP_OVERFLOW" -> GroupOverflow,
    "LENGTH_MISMATCH" -> LengthMismatch,
    "BAD_GRID" -> BadGrid,
    "BOX_INVERTED" -> BoxInverted,
    "KEY_TOO_WIDE" -> KeyTooWide,
    "BAD_COMMAND" -> BadCommand
  )
  def name(code: Int): String = names.find(_._2 == code).map(_._1).getOrElse(s"UNKNOWN($code)")
}

/** Every parameter of the binning device, checked once here.
  *
  * The device bins a frame's boxes into the cells of a uniform grid and runs
  * each cell's all-pairs test on one of G lane groups of g lanes; the group
  * of cell (cx, cy, cz) is (cx mod 2^ax, cy mod 2^ay, cz mod 2^az). A box
  * covers at most two cells per axis, and two neighbouring cells differ in
  * their group, so a box puts at most one entry into each group.
  *
  * Keys: kw = keyWidth bits. A frame's shift s (<= localBits) splits a key into
  * its cell coordinate key >> s (< 2^cellBits) and its offset in the cell
  * (s bits). Entries keep the offsets only, clamped to their cell (see
  * [[BinEntry]]), so an entry holds 6 * localBits key bits.
  *
  * @param groupBits        (ax, ay, az): groups per axis 2^a, each a >= 1
  * @param lanesPerGroup    g: pair tests per cycle of one group
  * @param keyWidth         kw: bits of a key (cellBits + localBits)
  * @param cellBits         grid cells per axis <= 2^cellBits
  * @param boxCapacity      boxes per frame
  * @param groupCapacity    entries one group's memory holds
  * @param intakeBoxes      w: boxes accepted per cycle
  * @param pairsPerBeat     P: pairs sent per cycle; also the merge's clusters
  * @param memoryOutputStages registers after the entry and order memories' read
  * @param memoryStyle      how those memories are built (see bpaccel.MemoryStyle)
  * @param laneQueueDepth   entries queued per group and intake lane before the group writes them
  * @param maskQueueDepth   intake beats queued per group
  * @param cellQueueDepth   cells the walker reads ahead of the reader, per group
  * @param hitQueueDepth    hit beats (one schedule cycle's hits) queued per group
  * @param mergeQueueDepth  pairs each merge cluster queues, and beats the output queue holds
  * @param counterWidth     bits of the cycle counters (the formal checks narrow them)
  * @param debugPort        probes for the cycle-by-cycle comparison with the golden model
  * @param faults           deliberate bugs for the mutant tests; empty for every real build
  */
case class BinningParams(
  groupBits: Seq[Int] = Seq(2, 2, 1),
  lanesPerGroup: Int = 2,
  keyWidth: Int = 12,
  cellBits: Int = 4,
  boxCapacity: Int = 8192,
  groupCapacity: Int = 1024,
  intakeBoxes: Int = 4,
  pairsPerBeat: Int = 8,
  memoryOutputStages: Int = 2,
  memoryStyle: MemoryStyle = MemoryStyle.Inferred,
  laneQueueDepth: Int = 2,
  maskQueueDepth: Int = 4,
  cellQueueDepth: Int = 4,
  hitQueueDepth: Int = 8,
  mergeQueueDepth: Int = 2,
  counterWidth: Int = 64,
  debugPort: Boolean = false,
  faults: Set[BinningFault] = Set.empty
) {
  require(groupBits.length == 3, s"groupBits must give (ax, ay, az), got ${groupBits.mkString(", ")}")
  require(cellBits >= 1 && cellBits <= 8, s"cellBits must lie in 1..8 (the header's dims are 8-bit fields), got $cellBits")
  require(groupBits.forall(a => a >= 1 && a <= cellBits),
    s"each of groupBits must lie in 1..cellBits = $cellBits (two neighbouring cells need different groups), got ${groupBits.mkString(", ")}")
  require(lanesPerGroup >= 1 && lanesPerGroup <= 64, s"lanesPerGroup must lie in 1..64, got $lanesPerGroup")
  require(keyWidth >= cellBits + 1 && keyWidth <= 32,
    s"keyWidth must lie in cellBits + 1 = ${cellBits + 1} .. 32, got $keyWidth")
  require(boxCapacity >= 2 && boxCapacity <= (1 << 24), s"boxCapacity must lie in 2 .. 2^24, got $boxCapacity")
  require(groupCapacity >= 1 && groupCapacity <= (1 << 20), s"groupCapacity must lie in 1 .. 2^20, got $groupCapacity")
  require(intakeBoxes >= 1 && intakeBoxes <= 16, s"intakeBoxes must lie in 1..16, got $intakeBoxes")
  require(memoryOutputStages >= 0 && memoryOutputStages <= 4, s"memoryOutputStages must lie in 0..4, got $memoryOutputStages")
  require(memoryStyle != MemoryStyle.Ecp5OutputRegister || memoryOutputStages >= 1,
    s"memoryStyle ${MemoryStyle.Ecp5OutputRegister.name} keeps the first output register in the block RAM, " +
      s"so it needs memoryOutputStages >= 1, got $memoryOutputStages")
  require(laneQueueDepth >= 1 && maskQueueDepth >= 1 && cellQueueDepth >= 1,
    s"queue depths must be at least 1, got lane $laneQueueDepth, mask $maskQueueDepth, cell $cellQueueDepth")
  require(hitQueueDepth >= 2, s"hitQueueDepth must be at least 2, got $hitQueueDepth")
  require(mergeQueueDepth >= 2, s"mergeQueueDepth must be at least 2 (one pair or beat a cycle), got $mergeQueueDepth")
  require(counterWidth >= 4 && counterWidth <= 64, s"counterWidth must lie in 4..64, got $counterWidth")

  /** G: lane groups. */
  val groups: Int = 1 << groupBits.sum
  /** g. */
  val g: Int = lanesPerGroup
  /** m = G * g: pair tests per cycle of the whole device. */
  val lanes: Int = groups * g
  require(pairsPerBeat >= 1 && pairsPerBeat <= groups, s"pairsPerBeat must lie in 1..groups = $groups, got $pairsPerBeat")

  /** Bits of a key's offset within its cell; the largest legal shift. */
  val localBits: Int = keyWidth - cellBits
  val maxShift: Int  = localBits
  /** Bits of the shift field the core keeps (0 .. maxShift). */
  val shiftWidth: Int = log2Ceil(maxShift + 1)
  /** Bits of a cell coordinate and of a dimension (1 .. 2^cellBits). */
  val dimWidth: Int = cellBits + 1

  /** Bits of a group's local cell coordinate on each axis, and of the whole local cell number. */
  val localCellBitsPerAxis: Seq[Int] = groupBits.map(cellBits - _)
  val localCellBits: Int = localCellBitsPerAxis.sum.max(1)
  /** Rows of each group's cell table (its most local cells). */
  val localCells: Int = 1 << localCellBitsPerAxis.sum

  val indexWidth: Int = log2Ceil(boxCapacity).max(1)
  val countWidth: Int = log2Ceil(boxCapacity + 1)
  val entryAddrWidth: Int = log2Ceil(groupCapacity).max(1)
  val entryCountWidth: Int = log2Ceil(groupCapacity + 1)
  val groupWidth: Int = groupBits.sum

  /** Bits of one group-memory entry: 6 clamped offsets, 3 "starts here" bits, the box index, the local cell. */
  val entryBits: Int = 6 * localBits + 3 + indexWidth + localCellBits

  /** Cycles from a read of the entry or order memory to its data. */
  val memoryReadLatency: Int = 1 + memoryOutputStages

  /** Items the reader may have read ahead of the window: its read latency through both memories, plus two. */
  val itemQueueDepth: Int = 2 * memoryReadLatency + 2

  /** Cycles from a schedule cycle (op) to its hits at the group's hit queue: compare register, AND register. */
  val hitLatency: Int = 2

  /** Groups each merge cluster serves: cluster c serves groups c, c + P, c + 2P, ... */
  def clusterGroups(cluster: Int): Seq[Int] = (cluster until groups by pairsPerBeat)

  /** The group of a cell and its local cell number (x fastest), as the device numbers them. */
  def groupOf(cell: Seq[Int]): Int =
    (0 until 3).map(a => (cell(a) & ((1 << groupBits(a)) - 1)) << groupBits.take(a).sum).sum
  def localCellOf(cell: Seq[Int]): Int =
    (0 until 3).map(a => (cell(a) >> groupBits(a)) << localCellBitsPerAxis.take(a).sum).sum

  /** A group's local cells per axis for a frame of `dims`: ceil(D / 2^a). */
  def localDims(dims: Seq[Int]): Seq[Int] = (0 until 3).map(a => (dims(a) + (1 << groupBits(a)) - 1) >> groupBits(a))

  /** Whether the mutant tests asked for this deliberate bug. */
  def has(fault: BinningFault): Boolean = faults.contains(fault)

  /** DP16KD block RAMs (18 Kbit, widest 512 x 36) the group memories need on ECP5
    * if each maps alone to block RAM: entry memory and order memory per group,
    * cell table per group when `tablesInBlockRam` (else LUT RAM). An estimate
    * for choosing parameters; synthesis reports the truth (docs/binning.md).
    */
  def dp16kdEstimate(tablesInBlockRam: Boolean = false): Int = {
    def blocks(depth: Int, width: Int): Int =
      Seq(16384 -> 1, 8192 -> 2, 4096 -> 4, 2048 -> 9, 1024 -> 18, 512 -> 36).map { case (d, w) =>
        ((depth + d - 1) / d) * ((width + w - 1) / w)
      }.min
    val perGroup = blocks(groupCapacity, entryBits) + blocks(groupCapacity, entryAddrWidth) +
      (if (tablesInBlockRam) blocks(localCells, entryCountWidth) else 0)
    groups * perGroup
  }

  /** One string naming the configuration; the host compares it with the C header's. */
  def fingerprint: String =
    s"arch=binning,groups=${groupBits.mkString("x")},g=$g,key_width=$keyWidth,cell_bits=$cellBits," +
      s"boxes=$boxCapacity,group_entries=$groupCapacity,intake=$intakeBoxes,pairs=$pairsPerBeat," +
      s"memstages=$memoryOutputStages,queues=$laneQueueDepth/$maskQueueDepth/$cellQueueDepth/$hitQueueDepth/$mergeQueueDepth," +
      s"debug=${if (debugPort) 1 else 0}" + (if (memoryStyle != MemoryStyle.Inferred) s",memory=${memoryStyle.name}" else "")
}
