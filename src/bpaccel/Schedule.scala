package bpaccel

/** Closed-form cost of the all-pairs schedule, shared by the generator, the C
  * header and the tests.
  *
  * Block b (A ports at row b, objects b*m .. b*m+m-1) slides the B window one
  * object per cycle from b*m+1 until lane 0's partner is the last object n-1,
  * so it takes n-1-b*m cycles; blocks run while b*m <= n-2, i.e. while some A
  * object still has a later partner.
  *
  * A bipartite run (`split` = na > 0: set A is objects 0 .. na-1, set B
  * na .. n-1, only A x B is tested; stream architecture) runs the A blocks
  * only, b*m <= na-1. Block b streams its first 2m-1 objects b*m+1 .. b*m+2m-1
  * as the triangular block does (they carry the next A block past the
  * window's top), then jumps to max(b*m+2m, na) .. n-1: it takes
  * min(n-1-b*m, 2m-1+nb) cycles, nb = n-na.
  */
object Schedule {
  /** The last A object of a run: n-2 for a triangular run (split 0), else split-1. */
  private def lastA(n: Long, split: Long): Long = if (split == 0) n - 2 else split - 1

  def blocks(n: Long, m: Int, split: Long = 0): Long = if (n < 2) 0 else lastA(n, split) / m + 1

  def issueCycles(n: Long, m: Int, split: Long = 0): Long = {
    require(split == 0 || (split >= 1 && split < n), s"split must be 0 or lie in 1 .. n-1, got split = $split, n = $n")
    if (n < 2) return 0
    val nb = blocks(n, m, split)
    // Blocks b < full jump past the prefix: base + 2m < na. They take 2m-1+(n-na) cycles each.
    val full = if (split == 0) 0L else (((split - 2L * m) + m - 1) / m).max(0L).min(nb)
    val fullCycles = full * (2L * m - 1 + (n - split))
    // The rest take n-1-b*m: sum over b = full .. nb-1.
    val rest = (nb - full) * (n - 1) - m.toLong * ((nb * (nb - 1) - full * (full - 1)) / 2)
    fullCycles + rest
  }
}
