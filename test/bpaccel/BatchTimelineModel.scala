package bpaccel

/** The golden timeline of a batch: the device's cycles when the host offers
  * every count and box as soon as the device can take it and the consumer
  * never stalls. Written from the protocol (BatchControl's description),
  * not from the registers.
  *
  * Cycle 0 takes the first count. Boxes are taken one a cycle in the order
  * the cell is sent, with overlapped loads while the cell before runs. A cell
  * starts once its boxes are in and the cell before it has ended; a run of
  * n objects keeps the device busy for startup + issue + overhead cycles and
  * then ends in one cycle of the front end. The head takes the next count at
  * the start (overlapped loads) or at the end of the cell before.
  */
object BatchTimelineModel {

  /** `run`: cycles of runs and of cell ends; `load`: every other cycle of the batch. */
  case class Cycles(load: Long, run: Long) {
    def total: Long = load + run
  }

  /** `splits`: each cell's split (none: all triangular). */
  def apply(p: AccelParams, sizes: Seq[Int], splits: Seq[Int] = Nil): Cycles = {
    require(sizes.nonEmpty, "a batch has at least one cell")
    var take    = 0L  // the head takes this cell's count
    var lastEnd = -1L // the cycle the cell before ended
    var run     = 0L
    for ((n, split) <- sizes.zipAll(splits, 0, 0)) {
      val taken    = take + n // the cycle of the last box taken (or of the count)
      val start    = math.max(taken + 1, lastEnd + 1)
      val launched = n >= 2 && n <= p.capacity
      val busy     = if (launched) p.fixedCycles(n) + Schedule.issueCycles(n, p.m, split) else 0L
      val end      = start + busy + 1
      run += busy + 1
      lastEnd = end
      take = if (p.overlapsLoads) start else end
    }
    Cycles(load = lastEnd + 1 - run, run = run)
  }
}
