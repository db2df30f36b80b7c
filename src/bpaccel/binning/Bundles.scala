package bpaccel.binning

import chisel3._
import chisel3.util._

import bpaccel.Aabb

/** The core's frame errors (codes from [[BinningErrorCode]]). */
object BinningError extends ChiselEnum {
  val None              = Value(BinningErrorCode.None.U)
  val CountOverCapacity = Value(BinningErrorCode.CountOverCapacity.U)
  val KeyOutOfGrid      = Value(BinningErrorCode.KeyOutOfGrid.U)
  val BoxSpansCells     = Value(BinningErrorCode.BoxSpansCells.U)
  val GroupOverflow     = Value(BinningErrorCode.GroupOverflow.U)
  val LengthMismatch    = Value(BinningErrorCode.LengthMismatch.U)
  val BadGrid           = Value(BinningErrorCode.BadGrid.U)
  val BoxInverted       = Value(BinningErrorCode.BoxInverted.U)
  val KeyTooWide        = Value(BinningErrorCode.KeyTooWide.U)
  val BadCommand        = Value(BinningErrorCode.BadCommand.U)
}

/** A FRAME command's header as the shell hands it over: n boxes follow, a key's cell is key >> shift, dims cells per axis. */
class FrameHeader extends Bundle {
  val n     = UInt(32.W)
  val shift = UInt(8.W)
  val dims  = Vec(3, UInt(8.W))
}

/** Up to `intakeBoxes` boxes of one frame, lowest lanes filled first, in
  * stream order. Every FRAME packet delivers at least one beat, and exactly
  * one with `last` (the packet's TLAST): a frame of no boxes sends one beat
  * with no valid box and `last`.
  */
class BoxBeat(p: BinningParams) extends Bundle {
  val boxes = Vec(p.intakeBoxes, Valid(new Aabb(p.keyWidth)))
  val last  = Bool()
}

/** A pair of overlapping boxes, global indices of the frame, i < j. */
class BinPair(p: BinningParams) extends Bundle {
  val i = UInt(p.indexWidth.W)
  val j = UInt(p.indexWidth.W)
}

/** Up to `pairsPerBeat` pairs, lowest lanes filled first. */
class PairBeat(p: BinningParams) extends Bundle {
  val pairs = Vec(p.pairsPerBeat, Valid(new BinPair(p)))
}

/** What the shell turns into the reply's trailer (and the counter registers). */
class FrameSummary(p: BinningParams) extends Bundle {
  val error   = BinningError()
  val detail  = UInt(32.W) // the first offending box, or the boxes received when the packet ended short; else 0
  val records = UInt(32.W) // pairs sent
  val boxes   = UInt(32.W) // boxes received (those past n too)
  val entries = UInt(32.W) // entries binned in all groups
  val maxGroupEntries = UInt(32.W) // entries of the fullest group (the host's slab decisions)
  val cycles       = UInt(p.counterWidth.W) // header accepted .. summary valid
  val intakeCycles = UInt(p.counterWidth.W) // header accepted .. the groups' first cycle
  val issueCycles  = UInt(p.counterWidth.W) // schedule cycles that compared, summed over the groups
  val stallCycles  = UInt(p.counterWidth.W) // cycles pairs were offered and not taken
}

/** The binning core's ports to the stream shell (docs/binning.md): the
  * frame's header and boxes in, abort, the pairs and the summary out.
  */
class BinningPorts(p: BinningParams) extends Bundle {
  val frame   = Flipped(Decoupled(new FrameHeader))
  val boxes   = Flipped(Decoupled(new BoxBeat(p)))
  val abort   = Input(Bool())
  val pairs   = Decoupled(new PairBeat(p))
  val summary = Decoupled(new FrameSummary(p))
}

/** One box's entry in one cell of a group: its key offsets in the cell,
  * clamped to it (a box that starts in an earlier cell has min offset 0 there,
  * one that ends in a later cell max offset 2^shift - 1), whether it starts in
  * this cell per axis, its index and the group's local cell number.
  * Clamping keeps overlap exact: two boxes that both cover a cell overlap
  * iff their clamped intervals do on every axis (docs/binning.md).
  */
class BinEntry(p: BinningParams) extends EntryKeys(p) {
  val cell = UInt(p.localCellBits.W)

  /** The fields a lane compares (the cell stays behind: the reader's tags say where cells end). */
  def keys: EntryKeys = {
    val k = Wire(new EntryKeys(p))
    k.min := min; k.max := max; k.starts := starts; k.index := index
    k
  }
}

/** What a lane compares of an entry: its clamped offsets, "starts here" bits and box index. */
class EntryKeys(p: BinningParams) extends Bundle {
  val min    = Vec(3, UInt(p.localBits.W))
  val max    = Vec(3, UInt(p.localBits.W))
  val starts = Vec(3, Bool())
  val index  = UInt(p.indexWidth.W)
}

/** A cell the walker found with two or more entries: where its entries start in the order memory. */
class CellRun(p: BinningParams) extends Bundle {
  val start = UInt(p.entryAddrWidth.W)
  val n     = UInt(p.entryCountWidth.W)
}

/** What the reader attaches to each entry it streams (see [[CellReader]]). */
class ItemTags(p: BinningParams) extends Bundle {
  val first       = Bool()                      // entry 0 of its cell: a bubble when it reaches lane 0
  val left        = UInt(p.entryCountWidth.W)   // n - 1 - p: lanes 0 .. left compare when it is in lane 0
  val capture     = Bool()                      // A object d of its block's successor
  val captureLane = UInt(log2Ceil(p.g).max(1).W) // d
  val nextBlock   = Bool()                      // the last entry of a block that has a successor
}

class StreamItem(p: BinningParams) extends Bundle {
  val entry = new EntryKeys(p)
  val tags  = new ItemTags(p)
}

/** One schedule cycle's hits of a group: lane k's pair and whether it hit. */
class HitBeat(p: BinningParams) extends Bundle {
  val hit   = Vec(p.g, Bool())
  val pairs = Vec(p.g, new BinPair(p))
}

/** Debug: a group's entry write (the writer's cycle) and its schedule cycles at the AND stage. */
class GroupProbe(p: BinningParams) extends Bundle {
  val write        = Valid(new Bundle {
    val address = UInt(p.entryAddrWidth.W)
    val index   = UInt(p.indexWidth.W)
  })
  val issue = Bool() // an issue's hits are at the AND stage (hitLatency cycles after its schedule cycle)
  val lanes = Vec(p.g, new Bundle {
    val valid = Bool()
    val i     = UInt(p.indexWidth.W)
    val j     = UInt(p.indexWidth.W)
    val hit   = Bool()
  })
}
