package bpaccel

/** Golden model of the schedule, written from the seed's prose rather than
  * from the hardware: it plays the A and B port addresses and the
  * multiplexer selectors cycle by cycle and reads off which objects meet in
  * each lane. It knows nothing of window starts, lane masks or formulas.
  *
  * Object k lives in memory k mod m at address k / m, so memory `mem` at
  * address `addr` holds object addr * m + mem.
  */
object SeedScheduleModel {

  /** One lane in one cycle: the pair it tests, or None when it is idle (its B
    * object lies past the last AABB). The pair is (A object, B object) as read,
    * not sorted, so a wrong schedule shows up as i >= j.
    */
  type Lane = Option[(Int, Int)]

  /** @param selectorModulus the modulus of the selector increment. The seed's
    *                        text says "mod m - 1"; the schedule is right only
    *                        with m (see SeedScheduleModelSpec). Must be >= 1.
    */
  def cycles(n: Int, m: Int, selectorModulus: Int): Vector[Vector[Lane]] = {
    require(m >= 1 && selectorModulus >= 1)
    val out = Vector.newBuilder[Vector[Lane]]
    def obj(mem: Int, addr: Int): Int = addr * m + mem

    // "This pattern continues until some A selects the second last AABB":
    // blocks run while the block's first A object is at most n-2.
    var blockAddr = 0
    while (n >= 2 && obj(0, blockAddr) <= n - 2) {
      val a = Array.fill(m)(blockAddr)                                  // every A at the block's address
      val b = Array.tabulate(m)(p => if (p == 0) blockAddr + 1 else blockAddr) // first B one ahead
      val sel = Array.tabulate(m)(k => (k + 1) % m)                      // selector k starts at k+1
      var nextB = 1 % m                                                  // "the second B is incremented" next
      // The block goes on while the B window still holds an object that exists.
      def windowStart: Int = (0 until m).map(p => obj(p, b(p))).min
      while (windowStart <= n - 1) {
        out += Vector.tabulate(m) { k =>
          val i = obj(k, a(k))
          val j = obj(sel(k), b(sel(k)))
          if (i < n && j < n) Some((i, j)) else None
        }
        b(nextB) += 1
        nextB = (nextB + 1) % m
        for (k <- 0 until m) sel(k) = (sel(k) + 1) % selectorModulus
      }
      blockAddr += 1
    }
    out.result()
  }

  def cycles(n: Int, m: Int): Vector[Vector[Lane]] = cycles(n, m, selectorModulus = m)

  /** Every pair the schedule tests, in order, with repetitions. */
  def testedPairs(n: Int, m: Int, selectorModulus: Int): Seq[(Int, Int)] =
    cycles(n, m, selectorModulus).flatMap(_.flatten)
}
