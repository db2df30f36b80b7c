package bpaccel.binning

import chisel3._
import chisel3.util._

/** Formal-only wrapper of a group's schedule: its reader, its g lanes and
  * its hit serializer, fed with free cells (consecutive runs of 2 .. entries
  * positions of the sorted order, as the walker queues them, at any times)
  * over free entries (any offsets and starts, given with their cell; an entry's index is its
  * position, as in a sorted group, where positions rise with box index
  * within a cell), with a free consumer. The harness plays both memories:
  * the order memory maps a position to itself, the entry memory returns the
  * entry, each with the memories' latency. The monitors see the cells and
  * entries given and the pairs the group hands out:
  *  - `pairs`: each pair is two positions a < b of one cell whose entries
  *    overlap with the exactly-once rule, and none comes twice;
  *  - `complete`: once no cell is left, the lanes are idle and the hit queue is
  *    empty, every such pair came out.
  */
class EngineFormalHarness(p: BinningParams, properties: Set[BinProperty] = Set(BinProperty.Pairs, BinProperty.Complete))
    extends Module {
  private val cap = p.groupCapacity
  val io = IO(new Bundle {
    val cell  = Input(Bool())                          // give a cell now
    val n     = Input(UInt(p.entryCountWidth.W))       // ... of n entries
    val entries = Input(Vec(cap, new EntryKeys(p)))     // ... these at its positions
    val stop  = Input(Bool())                          // no more cells from now on
    val ready = Input(Bool())                          // the consumer of pairs
  })
  private def check(property: BinProperty, cond: Bool, what: String): Unit =
    if (properties.contains(property)) assert(cond, s"[${property.name}] $what")

  val reader = Module(new CellReader(p))
  val engine = Module(new GroupEngine(p))
  val hits   = Module(new HitSerializer(p))

  // ---- entries: each cell's come with it (from a free input; ChiselTest's formal flow starts
  // registers at 0, so they cannot be left free); an entry's index is its position ----
  val entries = Reg(Vec(cap, new EntryKeys(p)))

  // ---- cells: consecutive runs, queued as the walker queues them ----
  val cells   = Module(new Queue(new CellRun(p), p.cellQueueDepth))
  val next    = RegInit(0.U(p.entryCountWidth.W)) // first position of the next cell
  val stopped = RegInit(false.B)
  val cellOf  = Reg(Vec(cap, UInt(log2Ceil(cap + 1).W))) // which cell each position was given to
  val cellsGiven = RegInit(0.U(log2Ceil(cap + 1).W))
  val gives   = io.cell && !stopped && !io.stop && io.n >= 2.U && next +& io.n <= cap.U && cells.io.enq.ready
  cells.io.enq.valid      := gives
  cells.io.enq.bits.start := next
  cells.io.enq.bits.n     := io.n
  when(gives) {
    next  := next + io.n
    cellsGiven := cellsGiven + 1.U
    for (k <- 0 until cap) when(k.U >= next && k.U < next + io.n) { cellOf(k) := cellsGiven; entries(k) := io.entries(k) }
  }
  when(io.stop) { stopped := true.B }

  // ---- the memories, with their latency ----
  reader.io.cells <> cells.io.deq
  reader.io.orderData := ShiftRegister(reader.io.orderRead.bits, p.memoryReadLatency)
  val position = reader.io.entryRead.bits(log2Ceil(cap).max(1) - 1, 0)
  val entryRead = Wire(new EntryKeys(p))
  entryRead := entries(position)
  entryRead.index := position
  reader.io.entryData := ShiftRegister(entryRead, p.memoryReadLatency)
  val noMore = stopped && !cells.io.deq.valid && reader.io.idle
  engine.io.items <> reader.io.items
  engine.io.hitFreed := hits.io.freed
  hits.io.hits := engine.io.hits
  hits.io.out.ready := io.ready

  // ---- monitors ----
  private def owed(i: Int, j: Int): Bool = {
    val (a, b) = (entries(i), entries(j))
    j.U < next && cellOf(i) === cellOf(j) &&
      (0 until 3).map(x => a.min(x) <= b.max(x) && b.min(x) <= a.max(x) && (a.starts(x) || b.starts(x))).reduce(_ && _)
  }
  private val pairIndex = (for (i <- 0 until cap; j <- i + 1 until cap) yield (i, j)).zipWithIndex
  val seen = RegInit(0.U(pairIndex.length.W))
  val out  = hits.io.out
  val now  = Wire(Vec(pairIndex.length, Bool()))
  now.foreach(_ := false.B)
  check(BinProperty.Pairs, !out.fire || (out.bits.i < out.bits.j && out.bits.j < next), "a pair is not a < b among the positions given")
  for (((i, j), k) <- pairIndex) when(out.fire && out.bits.i === i.U && out.bits.j === j.U) {
    check(BinProperty.Pairs, owed(i, j), s"pair ($i, $j) came out, but not of one cell, not overlapping or against the rule")
    check(BinProperty.Pairs, !seen(k), s"pair ($i, $j) came out twice")
    now(k) := true.B
  }
  seen := seen | now.asUInt
  val over = noMore && engine.io.idle && hits.io.empty
  for (((i, j), k) <- pairIndex)
    check(BinProperty.Complete, !over || seen(k) || !owed(i, j), s"the group finished without pair ($i, $j)")
}
