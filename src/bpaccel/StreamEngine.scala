package bpaccel

import chisel3._
import chisel3.util._

/** The stream architecture: the seed's schedule from one memory read a cycle.
  *
  * Schedule (the seed's): block b compares A objects base+k (base = b*m) with
  * B objects s+k, s = base+1 .. n-1, lane k masked once s+k >= n. So the B
  * objects of consecutive cycles form one stream R: block 0's objects
  * 1 .. n-1, then block 1's m+1 .. n-1, and so on. In issue cycle t the
  * window, an m-deep shift register, holds R[t .. t+m-1] (lane k = object
  * s+k); each issue shifts it by one lane and takes R[t+m] at the top from
  * the memory's one read port ([[StreamReader]]). A block's last m-1 lanes
  * already hold the next block's first objects, so blocks follow each other
  * without a bubble.
  *
  * A blocks sit in registers (`a`). The next block's A objects base+m+k pass
  * the window's top lane in cycle k of the current block; `aNext`, a shift
  * chain entered at the top, takes each there (so object base+m+k ends in
  * lane k after m shifts) and is copied into `a` at the block change.
  *
  * Objects 0 .. m are kept, as they are loaded, in m + 1 head registers of
  * their own, a shift chain beside the window. The cycle after a start
  * copies them at once: lane k + 1 into window lane k, lane k into `aNext`
  * lane k. So a run needs no window shifts of its own before it issues, and
  * a batch's next cell loads all its boxes, these included, while the
  * current cell runs.
  *
  * A run of L < m + 1 loaded boxes leaves its objects d = m + 1 - L lanes
  * up the chain (object j in lane j + d; d is the loader's head pad, read
  * with the start), and so in the window and the A block: a short run's
  * lanes k < d are masked, and its lane k compares objects k - d and
  * k - d + s. The mask leaves in the engine's lane order; the beat's bases
  * are moved down instead, iBase = base - d and jBase = s - d modulo
  * 2^indexWidth, so bit k is still the pair (iBase + k, jBase + k) taken
  * modulo 2^indexWidth, and a set bit (k >= d) never wraps. Runs of more
  * than one block have n >= m + 2 objects, so d = 0 for them.
  *
  * Bipartite runs (split na > 0: only objects 0 .. na-1 against na .. n-1)
  * keep this shape: blocks run for the A objects alone, and a block's
  * stream jumps from its first 2m-1 objects (which still carry the next A
  * block past the top lane) to max(base+2m, na); lanes whose B object is
  * in A, or whose A object is past na-1, are masked (see Schedule).
  *
  * Three modules, one job each: [[StreamReader]] (the memory and the stream
  * read ahead), [[StreamControl]] (the schedule and the wide enables'
  * decisions) and [[StreamLanes]] (the registers of every lane and the
  * comparators), which act [[StreamEngine.LaneLag]] cycles after the control
  * decides. Startup after the start: the first readLatency reads travel to
  * the window's entry. Pipeline: the lanes' lag, comparator register, AND
  * register.
  */
class StreamEngine(p: AccelParams) extends Engine(p) {
  val reader  = Module(new StreamReader(p))
  val control = Module(new StreamControl(p))
  val lanes   = Module(new StreamLanes(p))

  reader.io.write   := io.write
  reader.io.prepare := io.prepare
  reader.io.launch  := io.launch.valid
  reader.io.bipartiteLeft := control.io.bipartiteLeft
  reader.io.active  := control.io.active
  reader.io.issue   := control.io.issue

  control.io.prepare      := io.prepare
  control.io.launch       := io.launch
  control.io.headPad      := io.headPad
  control.io.writeOffered := io.writeOffered
  control.io.offeredHead  := io.write.bits.head
  control.io.loaded       := reader.io.loaded
  control.io.loadClear    := io.loadClear
  control.io.room         := io.room
  control.io.advance      := advance

  lanes.io.loaded := reader.io.loaded.bits
  lanes.io.entry  := reader.io.head
  lanes.io.headShift      := control.io.headShift
  lanes.io.headCopy       := control.io.headCopy
  lanes.io.windowWrite    := control.io.windowWrite
  lanes.io.aNextWrite     := control.io.aNextWrite
  lanes.io.aLoad          := control.io.aLoad
  lanes.io.splitLane      := control.io.splitLane
  lanes.io.issue          := control.io.issue
  lanes.io.laneHasObjects := control.io.laneHasObjects
  lanes.io.iBase          := control.io.iBase
  lanes.io.jBase          := control.io.jBase

  io.activity.active   := control.io.active
  io.activity.issued   := control.io.issue
  io.activity.stalled  := control.io.issuing && !advance
  io.activity.inFlight := lanes.io.inFlight
  io.activity.retired  := lanes.io.out.valid

  val atAnd = lanes.io.out
  val outValid =
    if (p.has(Fault.RepeatLastBeat)) atAnd.valid || (RegNext(atAnd.valid, false.B) && !atAnd.valid) else atAnd.valid
  emit(outValid, atAnd.bits.iBase, atAnd.bits.jBase, atAnd.bits.laneMask, atAnd.bits.probeI, atAnd.bits.probeJ,
    lanes.io.hits)
}

object StreamEngine {
  /** Lanes served by one register of each enable's group stage. */
  val LaneGroup = 8

  /** Cycles by which the lanes act after the control decides (see [[StreamLanes]]). */
  val LaneLag = 2

  def minOf(a: UInt, b: UInt): UInt = Mux(a < b, a, b)
  def maxOf(a: UInt, b: UInt): UInt = Mux(a > b, a, b)
}
