package bpaccel

import chisel3.util.log2Ceil

/** Every parameter of the generator, checked once here so that every module
  * can trust them.
  *
  * @param m                parallelism: lanes, i.e. pair tests per cycle (any m >= 1)
  * @param capacity         most objects one run can hold; a multiple of m
  * @param keyWidth         bits of one coordinate key (order-preserving image of a float32)
  * @param resultQueueDepth result beats buffered before the sequencer must stall
  * @param memoryOutputStages registers after each memory's read data. FPGA synthesis folds
  *                         the first into the block RAM's synchronous read, so it takes
  *                         two for the rotator to start from a fabric register (measured:
  *                         with one, the BRAM's clock-to-out fed the rotator directly)
  * @param debugPort        add a port that shows every lane's (i, j, valid) per cycle, for tests
  */
case class AccelParams(
  m: Int = 8,
  capacity: Int = AccelParams.defaultCapacity(8),
  keyWidth: Int = 32,
  resultQueueDepth: Int = 16,
  memoryOutputStages: Int = 2,
  debugPort: Boolean = false
) {
  require(m >= 1, s"parallelism m must be at least 1, got m = $m")
  require(capacity >= 2, s"capacity must be at least 2 objects, got capacity = $capacity")
  require(
    capacity % m == 0,
    s"capacity must be a multiple of m so the objects stripe evenly: capacity = $capacity, m = $m"
  )
  require(
    memoryOutputStages >= 0 && memoryOutputStages <= 4,
    s"memoryOutputStages must lie in 0..4, got $memoryOutputStages"
  )
  require(keyWidth >= 1 && keyWidth <= 64, s"keyWidth must lie in 1..64, got keyWidth = $keyWidth")
  require(m < (1 << 16) && capacity.toLong < (1L << 32), s"m must fit 16 bits and capacity 32 bits, got m = $m, capacity = $capacity")

  /** Rows of each of the m memories of a coordinate buffer. */
  val depth: Int = capacity / m

  /** Bits of an object index 0 .. capacity-1. */
  val indexWidth: Int = log2Ceil(capacity).max(1)

  /** Bits of an object count 0 .. capacity. */
  val countWidth: Int = log2Ceil(capacity + 1)

  /** Bits of a memory row address 0 .. depth-1. */
  val rowWidth: Int = log2Ceil(depth).max(1)

  /** Bits of a B-port row register, which may point one row past the last (depth). */
  val bRowWidth: Int = log2Ceil(depth + 1)

  /** Bits of a lane number / rotation amount 0 .. m-1. */
  val laneWidth: Int = log2Ceil(m).max(1)

  /** Cycles from an issue of the sequencer to its hit mask: memory read,
    * memory output registers, rotator register, comparator register.
    */
  val pipelineLatency: Int = 1 + memoryOutputStages + 2

  /** Cycles a run of n >= 2 objects takes beyond its issue cycles when the
    * consumer never stalls: the pipeline's latency plus the cycle that sees it
    * drained (the result queue passes beats through in the cycle they arrive).
    */
  val runOverheadCycles: Int = pipelineLatency + 1

  require(
    resultQueueDepth >= pipelineLatency + 2,
    s"resultQueueDepth must be at least pipelineLatency + 2 = ${pipelineLatency + 2} " +
      s"so a consumer that is always ready never stalls the sequencer, got $resultQueueDepth"
  )

  /** Width of a counter; 64 bits cannot overflow within any run this design can hold. */
  val counterWidth: Int = 64
}

object AccelParams {
  /** Rows per memory when no capacity is given: one block RAM's worth. */
  val defaultRows: Int = 256

  def defaultCapacity(m: Int): Int = defaultRows * m
}
