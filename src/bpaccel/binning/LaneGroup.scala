package bpaccel.binning

import chisel3._
import chisel3.util._

/** One lane group: its writer, cell table, entry and order memories, the
  * prefix and sort passes, the walker, the reader, the g lanes and the hit
  * serializer. After the intake (`start`), it runs prefix, sort and compute
  * on its own; `done` says its schedule, its hits and its table's clears are
  * over (its hit queue may still hold pairs: `empty`).
  */
class LaneGroup(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val in         = Flipped(new GroupPush(p))
    val frameStart = Input(Bool())
    val start      = Input(Bool()) // the intake is over: the prefix begins in the next cycle
    val clear      = Flipped(Valid(UInt(p.localCellBits.W))) // a table row to zero (after a reset, an abort or an error)
    val localDims  = Input(Vec(3, UInt((p.cellBits + 1).W)))
    val out        = Decoupled(new BinPair(p))
    val entries    = Output(UInt(p.entryCountWidth.W))
    val intakeIdle = Output(Bool())
    val done       = Output(Bool())
    val empty      = Output(Bool())
    val issues     = Output(UInt(GroupCounters.issueWidth(p).W))
    val probe      = Output(new GroupProbe(p))
  })
  val writer    = Module(new GroupWriter(p))
  val increment = Module(new TableIncrement(p))
  val prefix    = Module(new PrefixPass(p))
  val sort      = Module(new SortPass(p))
  val walker    = Module(new CellWalker(p))
  val reader    = Module(new CellReader(p))
  val engine    = Module(new GroupEngine(p))
  val hits      = Module(new HitSerializer(p))
  val entryMemory = Module(new BinMemory(p, p.groupCapacity, p.entryBits))
  val orderMemory = Module(new BinMemory(p, p.groupCapacity, p.entryAddrWidth))

  // ---- intake: entries in stream order, cells counted ----
  writer.io.in <> io.in
  writer.io.frameStart := io.frameStart
  entryMemory.io.write.valid     := writer.io.write.valid
  entryMemory.io.write.bits.row  := writer.io.count(p.entryAddrWidth - 1, 0)
  entryMemory.io.write.bits.data := writer.io.write.bits.asUInt
  increment.io.in.valid := writer.io.write.valid || sort.io.increment.valid
  increment.io.in.bits  := Mux(writer.io.write.valid, writer.io.write.bits.cell, sort.io.increment.bits)
  assert(!(writer.io.write.valid && sort.io.increment.valid), "the intake and the sort incremented the table at once")

  // ---- the cell table: one read and one write port, shared by phases that never overlap ----
  val table = Module(new CellTable(p))
  val users = Seq(increment.io.table, prefix.io.table, walker.io.table)
  val readers = users.map(_.read)
  val writers = users.map(_.write) :+ {
    val c = Wire(chiselTypeOf(walker.io.table.write))
    c.valid := io.clear.valid; c.bits.row := io.clear.bits; c.bits.data := 0.U
    c
  }
  // At most one valid: clearing the lowest set bit leaves none (every bit of v - 1 is used, unlike PopCount <= 1's sum).
  def atMostOne(valids: Seq[Bool]): Bool = { val v = VecInit(valids).asUInt; (v & (v - 1.U)) === 0.U }
  assert(atMostOne(readers.map(_.valid)) && atMostOne(writers.map(_.valid)), "two phases used the cell table at once")
  table.io.read.valid := readers.map(_.valid).reduce(_ || _)
  table.io.read.bits  := PriorityMux(readers.map(_.valid) :+ true.B, readers.map(_.bits) :+ 0.U)
  table.io.write.valid := writers.map(_.valid).reduce(_ || _)
  table.io.write.bits  := PriorityMux(writers.map(_.valid) :+ true.B, writers.map(_.bits) :+ writers.head.bits)
  users.foreach(_.readData := table.io.readData)

  // ---- prefix, sort, walk ----
  prefix.io.start := io.start
  prefix.io.localDims := io.localDims
  sort.io.start := prefix.io.next
  sort.io.entries := writer.io.count
  sort.io.entryCell := entryMemory.io.readData.asTypeOf(new BinEntry(p)).cell
  sort.io.cursor := increment.io.out
  orderMemory.io.write.valid     := sort.io.orderWrite.valid
  orderMemory.io.write.bits.row  := sort.io.orderWrite.bits.row
  orderMemory.io.write.bits.data := sort.io.orderWrite.bits.data
  walker.io.start := sort.io.next
  walker.io.localDims := io.localDims
  val computing = RegInit(false.B)
  when(sort.io.next) { computing := true.B }
  when(io.frameStart) { computing := false.B }

  // ---- compute: reader, lanes, hits ----
  reader.io.cells <> walker.io.cells
  orderMemory.io.read := reader.io.orderRead
  reader.io.orderData := orderMemory.io.readData
  entryMemory.io.read.valid := sort.io.entryRead.valid || reader.io.entryRead.valid
  entryMemory.io.read.bits  := Mux(sort.io.entryRead.valid, sort.io.entryRead.bits, reader.io.entryRead.bits)
  reader.io.entryData := entryMemory.io.readData.asTypeOf(new BinEntry(p)).keys
  val noMore = walker.io.done && !walker.io.cells.valid && reader.io.idle
  engine.io.items <> reader.io.items
  engine.io.hitFreed := hits.io.freed
  hits.io.hits := engine.io.hits
  io.out <> hits.io.out

  val issues = RegInit(0.U(GroupCounters.issueWidth(p).W))
  when(engine.io.issued) { issues := issues + 1.U }
  when(io.frameStart) { issues := 0.U }

  io.entries    := writer.io.count
  io.intakeIdle := writer.io.idle
  io.done       := computing && noMore && engine.io.idle
  io.empty      := hits.io.empty
  io.issues     := issues
  io.probe.write.valid        := writer.io.write.valid
  io.probe.write.bits.address := writer.io.count(p.entryAddrWidth - 1, 0)
  io.probe.write.bits.index   := writer.io.write.bits.index
  io.probe.issue := engine.io.probe.issue
  io.probe.lanes := engine.io.probe.lanes
}

/** A group's cell table: one row per local cell (a count, then a cursor,
  * then a cell's end), one read and one write port, the read a cycle late.
  * A read that meets a write of its row is never used (TableIncrement
  * forwards the write instead), so the memory needs no collision bypass.
  * It is small (localCells x entryCountWidth, 128 x 11 by default), so the
  * emitted module asks for LUT RAM (bpaccel.DistributedMemories) and leaves
  * the block RAM to the entry and order memories.
  */
class CellTable(p: BinningParams) extends Module {
  val io = IO(new Bundle {
    val read     = Flipped(Valid(UInt(p.localCellBits.W)))
    val readData = Output(UInt(p.entryCountWidth.W))
    val write    = Flipped(Valid(new Bundle { val row = UInt(p.localCellBits.W); val data = UInt(p.entryCountWidth.W) }))
  })
  val mem = SyncReadMem(p.localCells, UInt(p.entryCountWidth.W))
  when(io.write.valid) { mem.write(io.write.bits.row, io.write.bits.data) }
  io.readData := mem.read(io.read.bits, io.read.valid)
}

object CellTable {
  /** The memory module firtool emits for the table. */
  def memoryModule(p: BinningParams): String = s"mem_${p.localCells}x${p.entryCountWidth}"
}

object GroupCounters {
  /** Bits of a group's issue count: C(groupCapacity, 1) at most. */
  def issueWidth(p: BinningParams): Int = log2Ceil(p.groupCapacity.toLong * p.groupCapacity / 2 + 2).toInt
}
