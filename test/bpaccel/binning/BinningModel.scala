package bpaccel.binning

import bpaccel.{Box, StreamScheduleModel}

/** A FRAME command as the host sends it: the header (n, shift, dims) and the
  * boxes that follow it, in stream order. `n` defaults to the boxes sent;
  * a different n makes the packet's length wrong (LENGTH_MISMATCH).
  */
case class BinFrame(boxes: Seq[Box], shift: Int, dims: Seq[Int], header: Option[Int] = None) {
  require(dims.length == 3)
  def n: Int = header.getOrElse(boxes.length)
}

/** Golden model of the binning device's function, written from the design
  * brief (docs/binning.md), not from the hardware: which entries each box
  * makes, in which group and order; which frame errors; which pairs each cell
  * reports (the exactly-once rule); and each group's per-cell schedule.
  * The cycles are in [[BinningCycleModel]].
  */
object BinningModel {
  /** One box's entry in one cell: the cell's global coordinates and, per axis, whether the box starts there. */
  case class Entry(box: Int, cell: Seq[Int], starts: Seq[Boolean])

  /** What the device does with a frame: its error (code, detail) and each
    * group's entries in the order its memory receives them (with an error,
    * those of the boxes before the erring one: the device writes them, and
    * then reports no pair).
    */
  case class Binned(error: Int, detail: Long, groups: Vector[Vector[Entry]]) {
    def ok: Boolean = error == BinningErrorCode.None
    def entries: Int = groups.map(_.length).sum
  }

  private def cellOf(key: BigInt, shift: Int): Int = (key >> shift).toInt

  /** The cells of a box on one axis: lo and hi (hi = lo or lo + 1 for a legal box). */
  def cellSpan(b: Box, axis: Int, shift: Int): (Int, Int) = (cellOf(b.min(axis), shift), cellOf(b.max(axis), shift))

  /** Every cell a box covers, x fastest. */
  def cellsOf(b: Box, shift: Int): Seq[Seq[Int]] = {
    val spans = (0 until 3).map(a => cellSpan(b, a, shift))
    for (z <- spans(2)._1 to spans(2)._2; y <- spans(1)._1 to spans(1)._2; x <- spans(0)._1 to spans(0)._2)
      yield Seq(x, y, z)
  }

  /** The first error a box raises, if any (a box past n is LENGTH_MISMATCH whatever it holds). */
  private def boxError(p: BinningParams, f: BinFrame, index: Int): Option[Int] = {
    val b = f.boxes(index)
    def anyAxis(cond: Int => Boolean) = (0 until 3).exists(cond)
    if (index >= f.n) Some(BinningErrorCode.LengthMismatch)
    else if (anyAxis(a => b.min(a) > b.max(a))) Some(BinningErrorCode.BoxInverted)
    else if (anyAxis(a => cellOf(b.max(a), f.shift) >= f.dims(a))) Some(BinningErrorCode.KeyOutOfGrid)
    else if (anyAxis(a => cellOf(b.max(a), f.shift) - cellOf(b.min(a), f.shift) > 1)) Some(BinningErrorCode.BoxSpansCells)
    else None
  }

  /** The frame header's error, if any. */
  def headerError(p: BinningParams, f: BinFrame): Option[Int] =
    if (f.n > p.boxCapacity) Some(BinningErrorCode.CountOverCapacity)
    else if (f.shift > p.maxShift || f.dims.exists(d => d < 1 || d > (1 << p.cellBits))) Some(BinningErrorCode.BadGrid)
    else None

  /** Bins a frame: each box in stream order puts one entry into the group of
    * each cell it covers; the first error (in stream order) ends the frame.
    */
  def bin(p: BinningParams, f: BinFrame): Binned = {
    val empty = Vector.fill(p.groups)(Vector.empty[Entry])
    headerError(p, f) match {
      case Some(code) => return Binned(code, 0, empty)
      case None       =>
    }
    val groups = Array.fill(p.groups)(Vector.newBuilder[Entry])
    val counts = Array.fill(p.groups)(0)
    def sofar = groups.map(_.result()).toVector
    for (i <- f.boxes.indices) {
      boxError(p, f, i) match {
        case Some(code) => return Binned(code, i, sofar)
        case None       =>
      }
      val b       = f.boxes(i)
      val entries = cellsOf(b, f.shift).map(c => Entry(i, c, (0 until 3).map(a => c(a) == cellOf(b.min(a), f.shift))))
      val byGroup = entries.groupBy(e => p.groupOf(e.cell))
      require(byGroup.values.forall(_.length == 1), "a box put two entries into one group")
      if (byGroup.keys.exists(gr => counts(gr) + 1 > p.groupCapacity))
        return Binned(BinningErrorCode.GroupOverflow, i, sofar)
      for ((gr, Seq(e)) <- byGroup) { groups(gr) += e; counts(gr) += 1 }
    }
    if (f.boxes.length < f.n) return Binned(BinningErrorCode.LengthMismatch, f.boxes.length, sofar)
    Binned(BinningErrorCode.None, 0, groups.map(_.result()).toVector)
  }

  /** The exactly-once rule, stated geometrically: the pair is reported in the
    * cell holding the lower corner of the two boxes' intersection,
    * (max(min_a, min_b) >> shift) on each axis.
    */
  def reportsIn(a: Box, b: Box, cell: Seq[Int], shift: Int): Boolean =
    a.overlaps(b) && (0 until 3).forall(ax => cellOf(a.min(ax).max(b.min(ax)), shift) == cell(ax))

  /** The local cells of one group in the order the device walks them (x fastest, then y, then z), as global cells. */
  def scanOrder(p: BinningParams, dims: Seq[Int], group: Int): Seq[Seq[Int]] = {
    val local = p.localDims(dims)
    val classOf = (0 until 3).map(a => (group >> p.groupBits.take(a).sum) & ((1 << p.groupBits(a)) - 1))
    for (lz <- 0 until local(2); ly <- 0 until local(1); lx <- 0 until local(0))
      yield Seq(lx, ly, lz).zipWithIndex.map { case (l, a) => (l << p.groupBits(a)) + classOf(a) }
  }

  /** A group's cells in walk order, each with its entries' boxes in memory order (cells outside dims are empty). */
  def groupCells(p: BinningParams, f: BinFrame, binned: Binned, group: Int): Seq[(Seq[Int], Seq[Int])] = {
    val byCell = binned.groups(group).groupBy(_.cell)
    scanOrder(p, f.dims, group).map(c => c -> byCell.getOrElse(c, Vector.empty).map(_.box))
  }

  /** One schedule cycle of a group: a cell's first cycle, which loads its A
    * registers and compares nothing (`bubble`), or an issue cycle whose lanes
    * compare (i, j) and report a hit where the exactly-once rule says so.
    */
  case class Op(cell: Seq[Int], bubble: Boolean, lanes: Vector[Option[(Int, Int, Boolean)]])

  /** A group's schedule: for each cell of two or more entries, in walk order,
    * one bubble and then the stream schedule of its n entries on g lanes
    * (bpaccel.StreamScheduleModel: block b compares entries b*g + k with
    * b*g + 1 + d + k), mapped to the entries' boxes.
    */
  def groupOps(p: BinningParams, f: BinFrame, binned: Binned, group: Int): Vector[Op] =
    groupCells(p, f, binned, group).filter(_._2.length >= 2).flatMap { case (cell, boxes) =>
      val lanes = StreamScheduleModel.cycles(boxes.length, p.g, readLatency = 1)
      Op(cell, bubble = true, Vector.fill(p.g)(None)) +: lanes.map(cycle => Op(cell, bubble = false, cycle.map(_.map {
        case (a, b) => (boxes(a), boxes(b), reportsIn(f.boxes(boxes(a)), f.boxes(boxes(b)), cell, f.shift))
      })))
    }.toVector

  /** Every pair the device reports for a frame without error, as a multiset (a pair reported twice appears twice). */
  def reportedPairs(p: BinningParams, f: BinFrame): Seq[(Int, Int)] = {
    val binned = bin(p, f)
    require(binned.ok, s"frame has error ${BinningErrorCode.name(binned.error)}")
    (0 until p.groups).flatMap(gr => groupOps(p, f, binned, gr).flatMap(_.lanes.flatten.collect { case (i, j, true) => (i, j) }))
  }

  /** Issue cycles of a cell of n entries on g lanes: the stream schedule's C(n, g). */
  def issueCycles(n: Int, g: Int): Long = bpaccel.Schedule.issueCycles(n, g)
}
