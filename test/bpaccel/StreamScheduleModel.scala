package bpaccel

/** Golden model of the stream architecture's schedule, written from its
  * description rather than from the hardware: it moves object numbers
  * through an m-lane shift register (the B window) and m A registers, the
  * way the description says the boxes move, and reads off which objects meet
  * in each lane. It knows nothing of window starts, lane masks or formulas:
  * a lane is compared when its B object belongs to the block being run.
  *
  *  - Loading keeps objects 0 .. m aside. The start copies objects 1 .. m
  *    into window lanes 0 .. m-1 and objects 0 .. m-1 into the A registers
  *    (lanes past the loaded objects hold nothing useful); then the first
  *    reads travel to the window's entry.
  *  - The memory is read in block order: block b's B objects b*m+1 .. n-1,
  *    then block b+1's. Each issue shifts the window by one lane, the next
  *    object of that order entering the top lane.
  *  - In cycle d < m of a block, the top lane's object is copied into the
  *    next block's A register d. A block ends when lane 0 holds its last
  *    object; the next block's A registers then become the current ones.
  *  - A bipartite run (`split` = na > 0) tests A = objects 0 .. na-1 against
  *    B = na .. n-1 only. It runs the A blocks alone, and block b's B
  *    objects are b*m+1 .. b*m+2m-1 (which carry the next A block past the
  *    top lane), then max(b*m+2m, na) .. n-1. A lane is compared when its B
  *    object lies in B and its A object in A.
  */
object StreamScheduleModel {
  type Lane = Option[(Int, Int)]

  /** An object in a register, with the block whose B stream it belongs to (-1: none). */
  private case class Item(obj: Int, block: Int)
  private val Garbage = Item(-1, -1)

  case class Run(cycles: Vector[Vector[Lane]], startupCycles: Int)

  def run(n: Int, m: Int, readLatency: Int, split: Int = 0): Run = {
    require(m >= 1 && readLatency >= 1)
    require(split == 0 || (split >= 1 && split < n), s"split $split outside 1 .. n-1 = ${n - 1}")
    if (n < 2) return Run(Vector.empty, 0)
    val lastA  = if (split == 0) n - 2 else split - 1
    val blocks = lastA / m + 1
    def blockStream(b: Int): Seq[Int] = {
      val base = b * m
      if (split == 0) base + 1 until n
      else (base + 1 until (base + 2 * m).min(n)) ++ ((base + 2 * m).max(split) until n)
    }
    val stream = (0 until blocks).flatMap(b => blockStream(b).map(Item(_, b)))
    def inA(obj: Int) = obj >= 0 && (split == 0 || obj < split)
    def inB(obj: Int) = split == 0 || obj >= split

    val window = Array.fill(m)(Garbage)
    def shiftIn(item: Item): Unit = {
      for (k <- 0 until m - 1) window(k) = window(k + 1)
      window(m - 1) = item
    }
    // The start's copy: lane k takes object k+1, A register k object k; block 0's stream from object 1.
    for (k <- 0 until m) window(k) = if (k + 1 < n) Item(k + 1, 0) else Garbage
    val aNext = Array.tabulate(m)(k => if (k < n) k else -1)
    val startup = readLatency

    val out   = Vector.newBuilder[Vector[Lane]]
    var a     = aNext.clone()
    var block = 0
    var d     = 0
    var next  = m // the window holds stream(0 .. m-1); stream(m) enters next
    while (block < blocks) {
      out += Vector.tabulate(m) { k =>
        val b = window(k)
        if (b.block == block && inA(a(k)) && inB(b.obj)) Some((a(k), b.obj)) else None
      }
      if (d < m) aNext(d) = window(m - 1).obj
      val blockEnds = window(0).block == block && (window(0).obj == n - 1)
      shiftIn(if (next < stream.length) stream(next) else Garbage)
      next += 1
      d += 1
      if (blockEnds) { block += 1; a = aNext.clone(); d = 0 }
    }
    Run(out.result(), startup)
  }

  def cycles(n: Int, m: Int, readLatency: Int, split: Int = 0): Vector[Vector[Lane]] =
    run(n, m, readLatency, split).cycles

  def testedPairs(n: Int, m: Int, readLatency: Int, split: Int = 0): Seq[(Int, Int)] =
    cycles(n, m, readLatency, split).flatMap(_.flatten)
}
