package bpaccel.binning

import chisel3._
import chisel3.util._

/** Streams each queued cell's entries to the window, one read a cycle: a
  * cell of n entries streams entries 0 .. n-1 (block 0) and then, for each
  * further block b (while b*g <= n-2), entries b*g+1 .. n-1. Entry p of a
  * cell is read through the order memory (row start + p gives its address)
  * and then the entry memory. Each item carries what the window needs (see
  * [[ItemTags]]). The reader reads while the item queue has room counting
  * its reads in flight (a credit register), so an item always finds room,
  * and it starts the next cell in the cycle after its current one's last read.
  */
class CellReader(p: BinningParams) extends Module {
  private val g  = p.g
  private val le = p.memoryReadLatency
  val io = IO(new Bundle {
    val cells     = Flipped(Decoupled(new CellRun(p)))
    val orderRead = Valid(UInt(p.entryAddrWidth.W))
    val orderData = Input(UInt(p.entryAddrWidth.W))
    val entryRead = Valid(UInt(p.entryAddrWidth.W))
    val entryData = Input(new EntryKeys(p))
    val items     = Decoupled(new StreamItem(p))
    val idle      = Output(Bool()) // no cell under way, no read in flight, nothing queued
  })
  class Position extends Bundle {
    val start = UInt(p.entryAddrWidth.W)
    val n     = UInt(p.entryCountWidth.W)
    val pos   = UInt(p.entryCountWidth.W) // entry p of the cell
    val base  = UInt(p.entryCountWidth.W) // b * g of its block
  }
  val items   = Module(new Queue(new StreamItem(p), p.itemQueueDepth))
  val credits = RegInit(p.itemQueueDepth.U(log2Ceil(p.itemQueueDepth + 1).W))
  val active  = RegInit(false.B)
  val current = Reg(new Position)

  val head = Wire(new Position)
  head.start := io.cells.bits.start
  head.n     := io.cells.bits.n
  head.pos   := 0.U
  head.base  := 0.U
  val at    = Mux(active, current, head)
  val reads = credits =/= 0.U && (active || io.cells.valid)
  io.cells.ready := credits =/= 0.U && !active

  val tags = Wire(new ItemTags(p))
  val hasNextBlock = at.base +& g.U <= at.n - 2.U // another block: (b+1)*g <= n-2
  val lastOfBlock  = at.pos === at.n - 1.U
  val captured     = at.pos -& at.base -& g.U   // d of A object (b+1)*g + d
  tags.first       := at.pos === 0.U && at.base === 0.U
  tags.left        := at.n - 1.U - at.pos
  tags.capture     := hasNextBlock && at.pos >= at.base +& g.U && at.pos < at.base +& (2 * g).U
  tags.captureLane := captured(log2Ceil(g).max(1) - 1, 0)
  tags.nextBlock   := hasNextBlock && lastOfBlock
  when(reads) {
    current.start := at.start
    current.n     := at.n
    current.base  := Mux(lastOfBlock, at.base + g.U, at.base)
    current.pos   := Mux(lastOfBlock, at.base + (g + 1).U, at.pos + 1.U)
    active        := !lastOfBlock || hasNextBlock
  }
  credits := credits - reads.asUInt + items.io.deq.fire.asUInt

  // Order memory, then entry memory; the tags travel beside the data.
  io.orderRead.valid := reads
  io.orderRead.bits  := (at.start + at.pos)(p.entryAddrWidth - 1, 0)
  val orderValid = ShiftRegisters(reads, le, false.B, true.B)
  val orderTags  = ShiftRegister(tags, le)
  io.entryRead.valid := orderValid.last
  io.entryRead.bits  := io.orderData
  val entryValid = ShiftRegisters(orderValid.last, le, false.B, true.B)
  val entryTags  = ShiftRegister(orderTags, le)
  items.io.enq.valid      := entryValid.last
  items.io.enq.bits.entry := io.entryData
  items.io.enq.bits.tags  := entryTags
  assert(!items.io.enq.valid || items.io.enq.ready, "the reader's item queue overflowed")
  assert(credits +& items.io.count +& PopCount(orderValid ++ entryValid) === p.itemQueueDepth.U,
    "the reader's credits do not match its queue and reads in flight")
  io.items <> items.io.deq
  io.idle := !active && !(orderValid ++ entryValid).reduce(_ || _) && !items.io.deq.valid
}
