package bpaccel.binning

import scala.util.Random

import bpaccel.Box

/** Frames for the binning device's specs: every box legal (inside the grid,
  * at most two cells per axis) unless a test breaks one on purpose.
  */
object BinScenes {
  private def box(lo: Seq[Long], hi: Seq[Long]): Box = Box(lo.map(BigInt(_)), hi.map(BigInt(_)))

  /** A random grid for `p`: dims 1 .. 2^cellBits per axis (small ones often), shift 0 .. maxShift. */
  def grid(rng: Random, p: BinningParams): (Int, Seq[Int]) = {
    val maxDim = 1 << p.cellBits
    val dims   = Seq.fill(3)(if (rng.nextInt(3) == 0) 1 + rng.nextInt(maxDim) else 1 + rng.nextInt(maxDim.min(4)))
    (rng.nextInt(p.maxShift + 1), dims)
  }

  /** n boxes anywhere in the grid, each at most one cell wide (so at most two cells per axis). */
  def uniform(rng: Random, n: Int, shift: Int, dims: Seq[Int], maxExtent: Option[Long] = None): Seq[Box] = {
    val cell = 1L << shift
    Seq.fill(n) {
      val lo = (0 until 3).map(a => (rng.nextDouble() * dims(a) * cell).toLong)
      val hi = (0 until 3).map { a =>
        val ext = rng.nextLong(maxExtent.getOrElse(cell - 1).min(cell - 1) + 1)
        (lo(a) + ext).min(dims(a) * cell - 1)
      }
      box(lo, hi)
    }
  }

  /** Boxes that all cross a cell boundary on every axis the grid allows (two cells wide there). */
  def straddling(rng: Random, n: Int, shift: Int, dims: Seq[Int]): Seq[Box] = {
    val cell = 1L << shift
    Seq.fill(n) {
      val bounds = (0 until 3).map { a =>
        if (dims(a) < 2 || cell < 2) {
          val lo = rng.nextLong(dims(a) * cell)
          (lo, (lo + rng.nextLong(cell)).min(dims(a) * cell - 1))
        } else {
          val edge = (1 + rng.nextInt(dims(a) - 1)) * cell // a boundary inside the grid
          (edge - 1 - rng.nextLong(cell - 1).min(edge - 1), edge + rng.nextLong(cell - 1))
        }
      }
      box(bounds.map(_._1), bounds.map(_._2))
    }
  }

  /** Boxes all inside one cell (touching and identical ones included). */
  def oneCell(rng: Random, n: Int, shift: Int, dims: Seq[Int]): Seq[Box] = {
    val cell = 1L << shift
    val at   = (0 until 3).map(a => rng.nextInt(dims(a)) * cell)
    Seq.fill(n) {
      val lo = at.map(_ + rng.nextLong(cell))
      val hi = lo.zip(at).map { case (l, c) => (l + rng.nextLong(cell)).min(c + cell - 1) }
      box(lo, hi)
    }
  }

  /** Boxes on a coarse lattice whose faces and corners touch exactly, across cells too. */
  def touching(rng: Random, n: Int, shift: Int, dims: Seq[Int]): Seq[Box] = {
    val cell = 1L << shift
    val step = (cell / 2).max(1)
    Seq.fill(n) {
      val lo = (0 until 3).map(a => step * rng.nextInt(((dims(a) * cell) / step).toInt.max(1)))
      val hi = lo.zipWithIndex.map { case (l, a) => (l + (if (rng.nextBoolean()) step else 0)).min(dims(a) * cell - 1) }
      box(lo, hi)
    }
  }

  /** The named scenes for one random grid. */
  def all(rng: Random, n: Int, shift: Int, dims: Seq[Int]): Seq[(String, Seq[Box])] = Seq(
    "uniform" -> uniform(rng, n, shift, dims),
    "small boxes" -> uniform(rng, n, shift, dims, Some(((1L << shift) / 8).max(0))),
    "every box straddles" -> straddling(rng, n, shift, dims),
    "all in one cell" -> oneCell(rng, n, shift, dims),
    "touching" -> touching(rng, n, shift, dims)
  )

  /** A scene like the benchmark's (docs/binning.md): n boxes of sizes 0.5 .. 2.0 times
    * 0.7 .. 1.6 per axis, centres uniform in a cube of volume n / 0.05, clipped to it.
    */
  case class FloatBox(lo: Seq[Double], hi: Seq[Double])
  def benchLike(rng: Random, n: Int): (Seq[FloatBox], Double) = {
    val edge = math.cbrt(n / 0.05)
    val boxes = Seq.fill(n) {
      val size = 0.5 + 1.5 * rng.nextDouble()
      val ext  = Seq.fill(3)(size * (0.7 + 0.9 * rng.nextDouble()))
      val c    = Seq.fill(3)(rng.nextDouble() * edge)
      FloatBox(c.zip(ext).map { case (x, e) => (x - e / 2).max(0) }, c.zip(ext).map { case (x, e) => (x + e / 2).min(edge) })
    }
    (boxes, edge)
  }

  /** What a host does with float boxes: `cells` cells per axis over [0, edge], shift = localBits, keys
    * conservative (min rounded down, max up), so every float overlap is a key overlap.
    */
  def quantize(p: BinningParams, boxes: Seq[FloatBox], edge: Double, cells: Int): BinFrame = {
    val shift   = p.maxShift
    val quantum = edge / cells / (1 << shift)
    val top     = (cells.toLong << shift) - 1
    def key(x: Double, up: Boolean): Long = {
      val q = x / quantum
      (if (up) math.ceil(q) else math.floor(q)).toLong.max(0).min(top)
    }
    BinFrame(boxes.map(b => box(b.lo.map(key(_, up = false)), b.hi.map(key(_, up = true)))), shift, Seq.fill(3)(cells))
  }
}
