package bpaccel

/** Closed-form cost of the all-pairs schedule, shared by the generator, the C
  * header and the tests.
  *
  * Block b (A ports at row b, objects b*m .. b*m+m-1) slides the B window one
  * object per cycle from b*m+1 until lane 0's partner is the last object n-1,
  * so it takes n-1-b*m cycles; blocks run while b*m <= n-2, i.e. while some A
  * object still has a later partner.
  */
object Schedule {
  def blocks(n: Long, m: Int): Long = if (n < 2) 0 else (n - 2) / m + 1

  def issueCycles(n: Long, m: Int): Long =
    if (n < 2) 0
    else {
      val nb = blocks(n, m)
      // sum_{b=0}^{nb-1} (n - 1 - b*m)
      nb * (n - 1) - m.toLong * nb * (nb - 1) / 2
    }
}
