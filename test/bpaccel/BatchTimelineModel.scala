package bpaccel

/** The golden timeline of a batch: the device's cycles when the host offers
  * every count and box as soon as the device can take it and the consumer
  * never stalls. Written from the protocol (BatchControl's and
  * AccelParams.loadsHeadLast's descriptions), not from the registers.
  *
  * Cycle 0 takes the first count. Boxes are taken one a cycle in the order
  * the cell is sent; with overlapped loads objects 0 .. m wait until the
  * last launched run stopped issuing (they enter its B window). A cell
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

  def apply(p: AccelParams, sizes: Seq[Int]): Cycles = {
    require(sizes.nonEmpty, "a batch has at least one cell")
    var take         = 0L  // the head takes this cell's count
    var windowFreeAt = 0L  // first cycle the B window is free for objects 0 .. m
    var lastEnd      = -1L // the cycle the cell before ended
    var run          = 0L
    for (n <- sizes) {
      var taken = take // the cycle of the last box taken (or of the count)
      for (position <- 0 until n) {
        // The loader's numbering; past the capacity a box is refused and the numbering stops.
        val index     = math.min(p.batchLoadIndex(position, n), p.capacity)
        val waits     = p.overlapsLoads && index <= p.m
        taken = math.max(taken + 1, if (waits) windowFreeAt else 0L)
      }
      val start    = math.max(taken + 1, lastEnd + 1)
      val launched = n >= 2 && n <= p.capacity
      val busy     = if (launched) p.fixedCycles(n) + Schedule.issueCycles(n, p.m) else 0L
      if (launched) windowFreeAt = start + p.startupCycles(n) + Schedule.issueCycles(n, p.m) + 1
      val end = start + busy + 1
      run += busy + 1
      lastEnd = end
      take = if (p.overlapsLoads) start else end
    }
    Cycles(load = lastEnd + 1 - run, run = run)
  }
}
