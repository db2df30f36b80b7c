package bpaccel

import chisel3._
import chisel3.util._

/** One axis-aligned bounding box as six order-preserving keys. */
class Aabb(keyWidth: Int) extends Bundle {
  val min = Vec(3, UInt(keyWidth.W))
  val max = Vec(3, UInt(keyWidth.W))
}

/** One result beat: all hits of one schedule cycle.
  * Lane k set in `mask` means objects (iBase + k) and (jBase + k) overlap,
  * with iBase + k < jBase + k always.
  */
class ResultBeat(p: AccelParams) extends Bundle {
  val iBase = UInt(p.indexWidth.W)
  val jBase = UInt(p.indexWidth.W)
  val mask  = UInt(p.m.W)
}

/** Error codes of a run, also written into the C header. */
object AccelError {
  val width = 2
  val None              = 0
  val CountOverCapacity = 1 // start(n) with n > capacity
  val CountOverLoaded   = 2 // start(n) with fewer than n boxes loaded
  val LoadOverflow      = 3 // more than capacity boxes were loaded
  val names: Seq[(String, Int)] = Seq(
    "NONE" -> None,
    "COUNT_OVER_CAPACITY" -> CountOverCapacity,
    "COUNT_OVER_LOADED" -> CountOverLoaded,
    "LOAD_OVERFLOW" -> LoadOverflow
  )
}

class AccelStatus(p: AccelParams) extends Bundle {
  val busy   = Bool()
  val done   = Bool() // the last run ended (with or without error) and nothing started since
  val error  = UInt(AccelError.width.W)
  val loaded = UInt(p.countWidth.W)
}

class AccelCounters(p: AccelParams) extends Bundle {
  val loadCycles  = UInt(p.counterWidth.W) // first box loaded .. start accepted, both included (1 if no box)
  val cycles      = UInt(p.counterWidth.W) // start accepted .. done
  val issueCycles = UInt(p.counterWidth.W) // cycles the comparator array was given work
  val stallCycles = UInt(p.counterWidth.W) // cycles the sequencer waited on the result queue
  val hits        = UInt(p.counterWidth.W) // pairs reported (all handed to the consumer by done)
}

/** What one lane tested in one schedule cycle, seen at the comparator output. */
class LaneProbe(p: AccelParams) extends Bundle {
  val valid = Bool()
  val i     = UInt(p.indexWidth.W)
  val j     = UInt(p.indexWidth.W)
  val hit   = Bool()
}

class DebugProbe(p: AccelParams) extends Bundle {
  val cycleValid = Bool() // this cycle carries a scheduled comparison
  val lanes      = Vec(p.m, new LaneProbe(p))
}

/** The configuration as constant outputs, so a host can check that the model
  * it drives is the one its header describes.
  */
class AccelInfo extends Bundle {
  val m                 = UInt(16.W)
  val capacity          = UInt(32.W)
  val keyWidth          = UInt(8.W)
  val runOverheadCycles = UInt(8.W)
}
