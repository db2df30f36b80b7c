package bpaccel.binning

import scala.collection.mutable

/** Cycle model of the binning device, written from docs/binning.md's
  * description of its phases and queues (not from the RTL): it plays a frame
  * cycle by cycle and says in which cycle each entry is written, each
  * schedule cycle of each group happens (with its lanes), each output beat
  * leaves and the summary appears. Cycle 0 accepts the frame's header; the
  * consumer of pairs is ready in cycle t when `ready(t)`, and the host offers
  * its next beat of boxes when `offer(t)`. Every decision of a cycle reads
  * the state at the cycle's start; what a queue takes in a cycle is visible
  * from the next (chisel3.util.Queue, which never takes while full).
  *
  * Intake. From cycle 1 the boxes port is ready while the intake register
  * is empty or moves on in that cycle, until the beat with `last` is taken.
  * The register moves on when an error was raised before (the rest of the
  * packet is drained), when its beat raises one (BinningModel's rules, first
  * box first; the beat then queues nothing), or when each group it has
  * entries for has room: its beat queue is not full and neither is the lane
  * queue of each of the beat's boxes with an entry for it; those entries are
  * then queued. In each cycle its beat queue is not empty, a group's writer
  * writes the entry of the head beat's lowest box not yet written, and drops
  * the beat after its last. Intake ends in the first cycle T whose start
  * has the last beat taken, the register and every queue empty and no entry
  * written in T - 1 (its cell count lands in T).
  *
  * A frame with an error then clears every row of each group's cell table,
  * one a cycle in T + 1 .. T + localCells, and is finished in T + localCells.
  * Otherwise every group runs from P0 = T + 1: the prefix (one cell of its
  * walk a cycle, Lc = the product of the local dims); the sort from S0 =
  * P0 + Lc (one entry a cycle; the last cursor write lands
  * memoryReadLatency + 1 cycles after the last read); compute from
  * C0 = S0 + E + memoryReadLatency + 1, in which:
  *  - the walker reads one cell of the walk a cycle while the cell queue's
  *    count plus its read in flight is below its depth; a read returns in the
  *    next cycle, and a cell of two or more entries is then queued;
  *  - the reader reads one stream item a cycle while the item queue's count
  *    plus its items in flight is below its depth: the next of its current
  *    cell's stream, else the first of the cell queue's head, which it takes.
  *    A cell of n entries streams entries 0 .. n-1 (block 0), then for each
  *    further block b entries b*g+1 .. n-1. An item is queued 2 *
  *    memoryReadLatency cycles after its read (order memory, entry memory);
  *  - the window holds up to g items; after the cycle's shift the item
  *    queue's head enters its lowest empty lane;
  *  - a schedule cycle happens when the window holds every item it uses
  *    (lanes 0 .. min(n-1-p, g-1), p lane 0's entry: the lanes it compares;
  *    the successor block's A objects pass the top lane only while
  *    n-1-p >= g-1), and either lane 0's item is a cell's entry 0
  *    (a bubble: the A registers take the window's lanes) or the hit queue's
  *    count plus the issues in flight is below its depth (an issue);
  *  - an issue's hits are queued hitLatency cycles later as one beat, if any
  *    lane hit; the serializer offers the head beat's pairs one a cycle,
  *    lowest lane first;
  *  - a group is done in the first cycle whose start has no item to come, an
  *    empty window and no issue in flight.
  * Merge: each cycle, cluster c (groups c, c+P, ...) moves the pair of the
  * first offering group after its last grant into its queue unless it is
  * full, and all cluster queues' heads move together into the output queue
  * (lowest cluster first) unless it is full (both of mergeQueueDepth); io.pairs is its head.
  * The frame is finished in the first cycle whose start has every group done
  * and every queue of the output path empty. The summary is valid from the
  * next cycle: a frame finished in cycle t took t + 1 cycles.
  */
object BinningCycleModel {
  case class OpAt(cycle: Long, op: BinningModel.Op)
  case class BeatAt(cycle: Long, pairs: Seq[(Int, Int)])
  case class WriteAt(cycle: Long, group: Int, address: Int, box: Int)

  /** When each phase began: intake's end, the prefix (all groups), each group's sort and compute, and each group's end. */
  case class Phases(intakeDone: Long, prefix: Long, sort: Vector[Long], compute: Vector[Long], groupDone: Vector[Long])

  case class Result(
    error: Int,
    detail: Long,
    binned: BinningModel.Binned,
    writes: Vector[WriteAt],
    ops: Vector[Vector[OpAt]], // per group, every schedule cycle (bubbles too) and when it happened
    beats: Vector[BeatAt],     // io.pairs handshakes
    summaryCycle: Long,        // the first cycle the summary is valid: the frame's cycles
    stallCycles: Long,         // cycles io.pairs was valid and not ready
    boxesReceived: Long,
    intakeDone: Long,
    phases: Option[Phases]
  ) {
    def pairs: Seq[(Int, Int)] = beats.flatMap(_.pairs)
    def issueCycles: Long = ops.map(_.count(!_.op.bubble).toLong).sum
    def cycles: Long = summaryCycle
  }

  /** A FIFO of chisel3.util.Queue's timing: decisions read `count`; takes and gives are committed at the cycle's end. */
  private final class Fifo[T](val depth: Int) {
    val items = mutable.Queue.empty[T]
    def count: Int = items.length
    def full: Boolean = count >= depth
    def nonEmpty: Boolean = items.nonEmpty
    def head: T = items.head
  }

  /** One stream item of a group: entry `p` of cell `cell` (n entries), streamed in block `block`. */
  private case class Item(cell: Int, p: Int, block: Int, n: Int) {
    def first: Boolean = block == 0 && p == 0
    def left: Int = n - 1 - p
  }

  private def cellStream(cell: Int, n: Int, g: Int): Seq[Item] =
    (0 until (n - 2) / g + 1).flatMap { b =>
      val from = if (b == 0) 0 else b * g + 1
      (from until n).map(q => Item(cell, q, b, n))
    }

  /** The beats the host sends: `layout` gives each beat's box count (default: w a beat, the last beat the rest). */
  def beatsOf(boxes: Int, w: Int, layout: Option[Seq[Int]] = None): Vector[Vector[Int]] = layout match {
    case Some(sizes) =>
      require(sizes.sum == boxes && sizes.forall(s => s >= 0 && s <= w) && sizes.nonEmpty, s"bad beat layout $sizes")
      sizes.scanLeft(0)(_ + _).sliding(2).map { case Seq(a, b) => (a until b).toVector }.toVector
    case None =>
      if (boxes == 0) Vector(Vector.empty) else (0 until boxes).grouped(w).map(_.toVector).toVector
  }

  def run(
    p: BinningParams,
    f: BinFrame,
    ready: Long => Boolean = _ => true,
    offer: Long => Boolean = _ => true,
    layout: Option[Seq[Int]] = None,
    maxCycles: Long = 5000000L
  ): Result = {
    val binned = BinningModel.bin(p, f)
    val g      = p.g
    val le     = p.memoryReadLatency
    val lc     = p.localDims(f.dims).product

    // ---------------- intake ----------------
    val beatsIn = beatsOf(f.boxes.length, p.intakeBoxes, layout)
    val headerError = BinningModel.headerError(p, f).isDefined
    // The box whose error ends the frame (n itself: the packet ended short).
    val erring: Option[Long] = if (binned.ok || headerError) None else Some(binned.detail)
    def beatErrs(k: Int): Boolean = erring.exists(d => beatsIn(k).contains(d.toInt) ||
      (k == beatsIn.length - 1 && binned.error == BinningErrorCode.LengthMismatch && d == f.boxes.length))
    // Each box's entries (only those binning keeps: none at or after the error), by group and lane.
    val entriesOf: Map[Int, Seq[(Int, BinningModel.Entry)]] =
      binned.groups.zipWithIndex.flatMap { case (es, gr) => es.map(e => (e.box, (gr, e))) }.groupMap(_._1)(_._2)
    def beatEntries(k: Int): Map[Int, Seq[(Int, BinningModel.Entry)]] = // group -> (lane, entry), lanes rising
      beatsIn(k).zipWithIndex.flatMap { case (box, lane) => entriesOf.getOrElse(box, Nil).map { case (gr, e) => (gr, (lane, e)) } }
        .groupMap(_._1)(_._2).map { case (gr, es) => gr -> es.sortBy(_._1) }
    val laneQ = Array.fill(p.groups, p.intakeBoxes)(new Fifo[BinningModel.Entry](p.laneQueueDepth))
    val maskQ = Array.fill(p.groups)(new Fifo[Vector[Int]](p.maskQueueDepth))
    val headDone = Array.fill(p.groups)(Set.empty[Int])
    val writtenCount = Array.fill(p.groups)(0)
    val writes = Vector.newBuilder[WriteAt]
    var nextBeat = 0
    var register: Option[Int] = None
    var errorRaised = headerError
    var lastTaken = false
    var wroteLast = false
    var intakeDone = -1L
    var boxesReceived = 0L

    // ---------------- groups ----------------
    val groupOps = (0 until p.groups).map(gr => if (binned.ok) BinningModel.groupOps(p, f, binned, gr) else Vector.empty)
    val cellSizes = (0 until p.groups).map(gr =>
      if (binned.ok) BinningModel.groupCells(p, f, binned, gr).map(_._2.length).toVector else Vector.empty[Int])
    val ops        = Array.fill(p.groups)(Vector.newBuilder[OpAt])
    val opIndex    = Array.fill(p.groups)(0)
    val sortAt     = Array.fill(p.groups)(-1L)
    val computeAt  = Array.fill(p.groups)(-1L)
    val groupDone  = Array.fill(p.groups)(-1L)
    val walkNext   = Array.fill(p.groups)(0)
    val walkRead   = Array.fill(p.groups)(-1) // the cell read in the last cycle (returning in this one), -1: none
    val cellQ      = Array.fill(p.groups)(new Fifo[Int](p.cellQueueDepth))
    val pending    = Array.fill(p.groups)(mutable.Queue.empty[Item]) // the rest of the current cell's stream
    val itemReads  = Array.fill(p.groups)(mutable.Queue.empty[(Long, Item)]) // (cycle it is queued, item)
    val itemQ      = Array.fill(p.groups)(new Fifo[Item](p.itemQueueDepth))
    val window     = Array.fill(p.groups)(mutable.ArrayBuffer.empty[Item])
    val issuesLive = Array.fill(p.groups)(mutable.Queue.empty[(Long, Seq[(Int, Int)])]) // (cycle it is queued, hits)
    val hitQ       = Array.fill(p.groups)(new Fifo[Seq[(Int, Int)]](p.hitQueueDepth))
    val hitSent    = Array.fill(p.groups)(0)

    // ---------------- output ----------------
    val clusters  = (0 until p.pairsPerBeat).map(p.clusterGroups)
    val lastGrant = Array.fill(p.pairsPerBeat)(-1)
    val clusterQ  = Array.fill(p.pairsPerBeat)(new Fifo[(Int, Int)](p.mergeQueueDepth))
    val outQ      = new Fifo[Seq[(Int, Int)]](p.mergeQueueDepth)
    val beats     = Vector.newBuilder[BeatAt]
    var stalls    = 0L
    var finished  = -1L

    var t = 1L
    while (finished < 0) {
      if (t > maxCycles) throw new IllegalStateException(s"the model did not finish within $maxCycles cycles")

      // ======== decisions, all from the cycle's start state ========
      // intake
      val inIntake = intakeDone < 0
      val quiet = inIntake && lastTaken && register.isEmpty && maskQ.forall(_.count == 0) && !wroteLast
      val regErrs = register.exists(k => !errorRaised && beatErrs(k))
      val regPushes: Map[Int, Seq[(Int, BinningModel.Entry)]] =
        if (register.isEmpty || errorRaised || regErrs) Map.empty else beatEntries(register.get)
      val regMoves = register.isDefined && (errorRaised || regErrs || regPushes.forall { case (gr, es) =>
        !maskQ(gr).full && es.forall { case (lane, _) => !laneQ(gr)(lane).full }
      })
      val takes = inIntake && !quiet && !lastTaken && (register.isEmpty || regMoves) && nextBeat < beatsIn.length && offer(t)
      val writers = if (inIntake) (0 until p.groups).filter(gr => maskQ(gr).nonEmpty) else Seq.empty

      // groups
      case class GroupStep(walkRead: Boolean, returned: Int, readItem: Boolean, takeCell: Boolean, op: Boolean,
                           fill: Boolean, done: Boolean)
      val afterIntake = !inIntake && binned.ok
      val steps = (0 until p.groups).map { gr =>
        if (!afterIntake || t < computeAt(gr) || groupDone(gr) >= 0) GroupStep(false, -1, false, false, false, false, false)
        else {
          val returned = walkRead(gr)
          val walk     = walkNext(gr) < lc && cellQ(gr).count + (if (returned >= 0) 1 else 0) < p.cellQueueDepth
          val mayRead  = itemQ(gr).count + itemReads(gr).length < p.itemQueueDepth
          val takeCell = mayRead && pending(gr).isEmpty && cellQ(gr).nonEmpty
          val readItem = mayRead && (pending(gr).nonEmpty || cellQ(gr).nonEmpty)
          val noMore = walkNext(gr) >= lc && returned < 0 && cellQ(gr).count == 0 && pending(gr).isEmpty &&
            itemReads(gr).isEmpty && itemQ(gr).count == 0
          val win = window(gr)
          val op = win.nonEmpty && win.length > win.head.left.min(g - 1) && // every item it compares is in
            (win.head.first || hitQ(gr).count + issuesLive(gr).length < p.hitQueueDepth)
          val fill = (win.length - (if (op) 1 else 0)) < g && itemQ(gr).nonEmpty
          val done = noMore && win.isEmpty && issuesLive(gr).isEmpty
          GroupStep(walk, returned, readItem, takeCell, op, fill, done)
        }
      }

      // output path
      val outValid = outQ.nonEmpty
      val outTaken = outValid && ready(t)
      val moveOut  = !outQ.full && clusterQ.exists(_.nonEmpty)
      val grants = clusters.indices.flatMap { c =>
        val offering = clusters(c).indices.filter(k => hitQ(clusters(c)(k)).nonEmpty)
        if (clusterQ(c).full || offering.isEmpty) None
        else Some(c -> offering.find(_ > lastGrant(c)).getOrElse(offering.head))
      }
      val outputEmpty = hitQ.forall(_.count == 0) && clusterQ.forall(_.count == 0) && outQ.count == 0

      // ======== commit ========
      if (quiet) intakeDone = t
      if (inIntake && !quiet) {
        for (gr <- writers) {
          val head = maskQ(gr).head
          val lane = head.filterNot(headDone(gr).contains).min
          val e    = laneQ(gr)(lane).items.dequeue()
          writes += WriteAt(t, gr, writtenCount(gr), e.box)
          writtenCount(gr) += 1
          headDone(gr) += lane
          if (headDone(gr).size == head.length) { maskQ(gr).items.dequeue(); headDone(gr) = Set.empty }
        }
        if (regMoves) {
          if (regErrs) errorRaised = true
          for ((gr, es) <- regPushes) {
            maskQ(gr).items.enqueue(es.map(_._1).toVector)
            for ((lane, e) <- es) laneQ(gr)(lane).items.enqueue(e)
          }
          register = None
        }
        if (takes) {
          register = Some(nextBeat)
          boxesReceived += beatsIn(nextBeat).length
          if (nextBeat == beatsIn.length - 1) lastTaken = true
          nextBeat += 1
        }
        wroteLast = writers.nonEmpty
      }
      if (quiet && binned.ok) for (gr <- 0 until p.groups) {
        sortAt(gr) = t + 1 + lc
        computeAt(gr) = sortAt(gr) + writtenCount(gr) + le + 1
      }
      if (quiet && !binned.ok) finished = t + p.localCells // the clears of T + 1 .. T + localCells

      for ((s, gr) <- steps.zipWithIndex) {
        if (s.done && groupDone(gr) < 0) groupDone(gr) = t
        walkRead(gr) = -1
        if (s.walkRead) { walkRead(gr) = walkNext(gr); walkNext(gr) += 1 }
        if (s.takeCell) {
          val c = cellQ(gr).items.dequeue()
          pending(gr) ++= cellStream(c, cellSizes(gr)(c), g)
        }
        if (s.readItem) itemReads(gr).enqueue((t + 2 * le, pending(gr).dequeue()))
        if (s.returned >= 0 && cellSizes(gr)(s.returned) >= 2) cellQ(gr).items.enqueue(s.returned)
        if (s.op) {
          val expected = groupOps(gr)(opIndex(gr))
          require(expected.bubble == window(gr).head.first, s"group $gr, op ${opIndex(gr)}: the stream and the schedule disagree")
          ops(gr) += OpAt(t, expected)
          opIndex(gr) += 1
          if (!expected.bubble)
            issuesLive(gr).enqueue((t + p.hitLatency, expected.lanes.flatten.collect { case (i, j, true) => (i, j) }))
          window(gr).remove(0)
        }
        if (s.fill) window(gr) += itemQ(gr).items.dequeue()
        while (itemReads(gr).nonEmpty && itemReads(gr).head._1 == t) itemQ(gr).items.enqueue(itemReads(gr).dequeue()._2)
        while (issuesLive(gr).nonEmpty && issuesLive(gr).head._1 == t) {
          val hits = issuesLive(gr).dequeue()._2
          if (hits.nonEmpty) hitQ(gr).items.enqueue(hits)
        }
      }

      if (outValid && !ready(t)) stalls += 1
      if (outTaken) beats += BeatAt(t, outQ.items.dequeue())
      if (moveOut) outQ.items.enqueue(clusterQ.filter(_.nonEmpty).map(_.items.dequeue()).toSeq)
      for ((c, k) <- grants) {
        val gr   = clusters(c)(k)
        val head = hitQ(gr).head
        clusterQ(c).items.enqueue(head(hitSent(gr)))
        hitSent(gr) += 1
        if (hitSent(gr) == head.length) { hitQ(gr).items.dequeue(); hitSent(gr) = 0 }
        lastGrant(c) = k
      }
      if (finished < 0 && afterIntake && (0 until p.groups).forall(gr => groupDone(gr) >= 0) && outputEmpty)
        finished = t
      t += 1
    }
    if (binned.ok) for (gr <- 0 until p.groups)
      require(opIndex(gr) == groupOps(gr).length, s"group $gr ended after ${opIndex(gr)} of ${groupOps(gr).length} schedule cycles")
    val phases = Option.when(binned.ok)(Phases(intakeDone, intakeDone + 1, sortAt.toVector, computeAt.toVector, groupDone.toVector))
    Result(binned.error, binned.detail, binned, writes.result(), ops.map(_.result()).toVector, beats.result(),
      summaryCycle = finished + 1, stallCycles = stalls, boxesReceived = boxesReceived, intakeDone = intakeDone, phases = phases)
  }
}
