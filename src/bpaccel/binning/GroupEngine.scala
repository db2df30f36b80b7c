package bpaccel.binning

import chisel3._
import chisel3.util._

/** A group's g lanes: the stream schedule of each cell, cells back to back.
  *
  * The window holds the next g stream items (lane 0 first); after each
  * schedule cycle's shift the item queue's head enters the lowest empty lane.
  * A schedule cycle happens when the window holds every item it uses: lanes
  * 0 .. min(left, g-1), left = n-1-p of lane 0's entry p (so no cell waits
  * for the items of the cells after it). A block's next A objects pass the
  * top lane only while left >= g-1, when all lanes are needed anyway:
  *  - lane 0 holds a cell's entry 0: a bubble, in which the A registers take
  *    the window's lanes (entries 0 .. g-1 of the cell; past n they are
  *    never compared);
  *  - otherwise an issue, if the hit queue has room for one more beat
  *    counting the issues in flight (a credit register): lane k compares A(k)
  *    with window lane k while k <= left (lane 0's n-1-p). The block's next A
  *    objects pass the top lane in its first g issues and are captured into
  *    `aNext`; the block's last issue copies them into A.
  * Each lane tests overlap on the clamped offsets (inclusive) and the
  * exactly-once rule (on every axis one of the two starts in this cell);
  * compare and AND are registered, so hits reach the hit queue hitLatency
  * cycles after their issue.
  */
class GroupEngine(p: BinningParams) extends Module {
  private val g = p.g
  val io = IO(new Bundle {
    val items   = Flipped(Decoupled(new StreamItem(p)))
    val hits    = Valid(new HitBeat(p))   // an issue's hits, when any lane hit
    val hitFreed = Input(Bool())          // the hit queue let a beat go
    val idle    = Output(Bool())          // the window is empty and no issue is in flight
    val issued  = Output(Bool())          // an issue in this cycle
    val probe   = Output(new Bundle {
      val issue = Bool()
      val lanes = Vec(g, new Bundle { val valid = Bool(); val i = UInt(p.indexWidth.W); val j = UInt(p.indexWidth.W); val hit = Bool() })
    })
  })
  val window = Reg(Vec(g, new StreamItem(p)))
  val filled = RegInit(VecInit(Seq.fill(g)(false.B))) // lanes 0 .. v-1 hold items
  val a      = Reg(Vec(g, new EntryKeys(p)))
  val aNext  = Reg(Vec(g, new EntryKeys(p)))
  val credits = RegInit(p.hitQueueDepth.U(log2Ceil(p.hitQueueDepth + 1).W))

  val lane0   = window(0)
  // Lane min(left, g-1), the highest it compares, holds an item (lanes fill from 0).
  val usedFilled =
    if (g == 1) true.B
    else Mux(lane0.tags.left >= (g - 1).U, filled(g - 1), filled(lane0.tags.left(log2Ceil(g) - 1, 0)))
  val ready   = filled(0) && usedFilled
  val bubble  = ready && lane0.tags.first
  val issue   = ready && !lane0.tags.first && credits =/= 0.U
  val shifts  = bubble || issue

  // ---- shift, then fill the lowest empty lane ----
  val held = PopCount(filled)
  val fillAt = held - shifts.asUInt // lanes held after the shift
  io.items.ready := fillAt < g.U
  for (k <- 0 until g) {
    val above = if (k == g - 1) false.B else filled(k + 1)
    val keep  = Mux(shifts, above, filled(k))
    when(shifts && (k < g - 1).B) { window(k) := window((k + 1).min(g - 1)) }
    val enters = io.items.fire && fillAt === k.U
    when(enters) { window(k) := io.items.bits }
    filled(k) := keep || enters
  }

  // ---- A registers ----
  when(bubble) { for (k <- 0 until g) a(k) := window(k).entry }
  when(issue && lane0.tags.nextBlock) { a := aNext }
  val top = window(g - 1)
  for (k <- 0 until g)
    when(issue && filled(g - 1) && top.tags.capture && ((g == 1).B || top.tags.captureLane === k.U)) { aNext(k) := top.entry }

  // ---- lanes: overlap on the clamped offsets and the exactly-once rule, registered twice ----
  class Compared extends Bundle {
    val lanes  = Vec(g, Bool())      // compared
    val checks = Vec(g, Bool())      // six compares and the rule, per lane: all true
    val pairs  = Vec(g, new BinPair(p))
  }
  val strict = p.has(BinningFault.StrictCompare)
  def overlaps(x: EntryKeys, y: EntryKeys): Bool = (0 until 3).map { ax =>
    if (strict) x.min(ax) < y.max(ax) && y.min(ax) < x.max(ax) else x.min(ax) <= y.max(ax) && y.min(ax) <= x.max(ax)
  }.reduce(_ && _)
  def once(x: EntryKeys, y: EntryKeys): Bool =
    if (p.has(BinningFault.NoExactlyOnceRule)) true.B else (0 until 3).map(ax => x.starts(ax) || y.starts(ax)).reduce(_ && _)
  val comparedValid = RegNext(issue, false.B)
  val compared = Reg(new Compared)
  for (k <- 0 until g) {
    compared.lanes(k)   := (if (p.has(BinningFault.LaneMaskOneTooWide)) lane0.tags.left +& 1.U >= k.U else lane0.tags.left >= k.U)
    compared.checks(k)  := overlaps(a(k), window(k).entry) && once(a(k), window(k).entry)
    compared.pairs(k).i := a(k).index
    compared.pairs(k).j := window(k).entry.index
  }
  val andedValid = RegNext(comparedValid, false.B)
  val anded = Reg(new Compared)
  anded.lanes  := compared.lanes
  anded.checks := VecInit((0 until g).map(k => compared.lanes(k) && compared.checks(k)))
  anded.pairs  := compared.pairs
  val anyHit = anded.checks.asUInt.orR
  io.hits.valid      := andedValid && anyHit
  io.hits.bits.hit   := anded.checks
  io.hits.bits.pairs := anded.pairs
  require(p.hitLatency == 2)

  credits := credits - issue.asUInt + (andedValid && !anyHit).asUInt + io.hitFreed.asUInt
  io.idle   := !filled(0) && !comparedValid && !andedValid
  io.issued := issue

  io.probe.issue := andedValid
  for (k <- 0 until g) {
    io.probe.lanes(k).valid := andedValid && anded.lanes(k)
    io.probe.lanes(k).i     := anded.pairs(k).i
    io.probe.lanes(k).j     := anded.pairs(k).j
    io.probe.lanes(k).hit   := andedValid && anded.checks(k)
  }
}
