package bpaccel

import scala.util.Random

/** A box of integer keys, and the plain all-pairs reference the hardware must match. */
case class Box(min: Seq[BigInt], max: Seq[BigInt]) {
  require(min.length == 3 && max.length == 3)
  def overlaps(o: Box): Boolean = (0 until 3).forall(a => min(a) <= o.max(a) && o.min(a) <= max(a))
}

object Box {
  /** Every overlapping pair i < j; with a split na > 0, only those with i < na <= j. */
  def bruteForcePairs(boxes: Seq[Box], split: Int = 0): Set[(Int, Int)] =
    (for {
      i <- boxes.indices
      j <- (i + 1) until boxes.length
      if split == 0 || (i < split && j >= split)
      if boxes(i).overlaps(boxes(j))
    } yield (i, j)).toSet

  /** Scene generators that stress the exact cases: many hits, touching faces,
    * zero extent, identical boxes, keys at 0 and at the maximum.
    */
  object Scenes {
    def maxKey(keyWidth: Int): BigInt = (BigInt(1) << keyWidth) - 1

    private def box(lo: Seq[BigInt], ext: Seq[BigInt], keyWidth: Int): Box =
      Box(lo, lo.zip(ext).map { case (l, e) => (l + e).min(maxKey(keyWidth)) })

    def uniform(rng: Random, n: Int, keyWidth: Int, span: BigInt, maxExtent: BigInt): Seq[Box] =
      Seq.fill(n)(box(Seq.fill(3)(BigInt(span.bitLength, rng) % span), Seq.fill(3)(BigInt(maxExtent.bitLength, rng) % (maxExtent + 1)), keyWidth))

    /** Boxes on a coarse grid with extent 0 or one grid step: faces and corners touch exactly. */
    def touching(rng: Random, n: Int, keyWidth: Int): Seq[Box] = {
      val step = BigInt(10)
      Seq.fill(n)(box(Seq.fill(3)(step * rng.nextInt(4)), Seq.fill(3)(if (rng.nextBoolean()) step else BigInt(0)), keyWidth))
    }

    /** A few identical boxes repeated, plus zero-extent points inside them. */
    def identicalAndPoints(rng: Random, n: Int, keyWidth: Int): Seq[Box] = {
      val protos = Seq.fill(3)(box(Seq.fill(3)(BigInt(rng.nextInt(50))), Seq.fill(3)(BigInt(rng.nextInt(30))), keyWidth))
      Seq.fill(n) {
        val p = protos(rng.nextInt(protos.length))
        if (rng.nextInt(3) == 0) { val pt = p.min.map(_ + 1).zip(p.max).map { case (a, b) => a.min(b) }; Box(pt, pt) }
        else p
      }
    }

    /** Boxes pinned to the ends of the key range. */
    def extremes(rng: Random, n: Int, keyWidth: Int): Seq[Box] = {
      val top = maxKey(keyWidth)
      Seq.fill(n) {
        val lo = Seq.fill(3)(if (rng.nextBoolean()) BigInt(0) else top - rng.nextInt(3))
        val hi = lo.map(l => if (rng.nextBoolean()) top else l)
        Box(lo, hi)
      }
    }

    def all(rng: Random, n: Int, keyWidth: Int): Seq[(String, Seq[Box])] = Seq(
      "dense cluster" -> uniform(rng, n, keyWidth, span = 40, maxExtent = 15),
      "sparse" -> uniform(rng, n, keyWidth, span = maxKey(keyWidth), maxExtent = maxKey(keyWidth) / 8),
      "touching faces" -> touching(rng, n, keyWidth),
      "identical boxes and points" -> identicalAndPoints(rng, n, keyWidth),
      "keys at 0 and max" -> extremes(rng, n, keyWidth)
    )
  }
}
