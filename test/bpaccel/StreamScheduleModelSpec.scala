package bpaccel

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import scala.util.Random

class StreamScheduleModelSpec extends AnyFlatSpec with Matchers {

  private def allPairs(n: Int): Seq[(Int, Int)] = for (i <- 0 until n; j <- i + 1 until n) yield (i, j)

  /** Small exhaustive grid plus larger and random cases, as for the seed's schedule. */
  private val cases: Seq[(Int, Int)] = {
    val small  = for (m <- 1 to 16; n <- 0 to 4 * m + 4) yield (m, n)
    val larger = for (m <- Seq(1, 2, 7, 8, 13, 16, 32, 64, 128); n <- Seq(100, 257, 512, 513)) yield (m, n)
    val rng    = new Random(9)
    val random = Seq.fill(40)((1 + rng.nextInt(40), rng.nextInt(400)))
    small ++ larger ++ random
  }
  private val latencies = Seq(2, 4) // memoryOutputStages 0 and 2, plus the memory's read and the read queue's head

  "The stream schedule" should "test every pair i < j exactly once and nothing else" in {
    for ((m, n) <- cases; l <- latencies) withClue(s"m=$m n=$n readLatency=$l: ") {
      val tested = StreamScheduleModel.testedPairs(n, m, l)
      all(tested.map { case (i, j) => i < j }) shouldBe true
      tested.sorted shouldBe allPairs(n) // same multiset: no miss, no repeat
    }
  }

  it should "take exactly the seed's issue cycles" in {
    for ((m, n) <- cases) withClue(s"m=$m n=$n: ") {
      StreamScheduleModel.cycles(n, m, 3).length.toLong shouldBe Schedule.issueCycles(n, m)
    }
  }

  it should "put the same pairs in the same lanes in the same cycles as the seed's" in {
    // So both architectures send the same result beats, and one host model serves both.
    for ((m, n) <- cases) withClue(s"m=$m n=$n: ") {
      StreamScheduleModel.cycles(n, m, 3) shouldBe SeedScheduleModel.cycles(n, m)
    }
  }

  /** Every split of the small grid, a few of each larger case. */
  private val splitCases: Seq[(Int, Int, Int)] = {
    val rng = new Random(10)
    cases.filter(_._2 >= 2).flatMap { case (m, n) =>
      if (n <= 4 * m + 4) (1 until n).map(na => (m, n, na))
      else (Seq(1, 2, m, m + 1, 2 * m, 2 * m + 1, n / 2, n - 2 * m, n - m, n - 1) ++ Seq.fill(3)(1 + rng.nextInt(n - 1)))
        .filter(na => na >= 1 && na < n).distinct.map(na => (m, n, na))
    }
  }

  "A bipartite stream run" should "test every pair of A x B exactly once and nothing else" in {
    for ((m, n, na) <- splitCases) withClue(s"m=$m n=$n split=$na: ") {
      val tested = StreamScheduleModel.testedPairs(n, m, 2, na)
      tested.sorted shouldBe (for (i <- 0 until na; j <- na until n) yield (i, j))
    }
  }

  it should "take the closed form's issue cycles, at most (2m-1+nb) per A block" in {
    for ((m, n, na) <- splitCases) withClue(s"m=$m n=$n split=$na: ") {
      val cycles = StreamScheduleModel.cycles(n, m, 2, na).length.toLong
      cycles shouldBe Schedule.issueCycles(n, m, na)
      cycles should be <= Schedule.blocks(n, m, na) * (2L * m - 1 + (n - na))
    }
  }

  it should "cut the cycles of a cell over capacity by 40 % at n = 8000 (m = 8, capacity 2048)" in {
    // The host cuts such a cell into chunks of capacity/2. Triangular runs of
    // every chunk pair test each chunk's inside pairs again in every pair;
    // bipartite runs test them once, in one triangular run per chunk.
    val (n, m, chunk) = (8000, 8, 1024)
    val sizes       = (0 until n by chunk).map(first => chunk.min(n - first))
    val chunkPairs  = for (p <- sizes.indices; q <- p + 1 until sizes.length) yield (sizes(p), sizes(q))
    val triangular  = chunkPairs.map { case (a, b) => Schedule.issueCycles(a + b, m) }.sum
    val bipartite   = sizes.map(c => Schedule.issueCycles(c, m)).sum +
      chunkPairs.map { case (a, b) => Schedule.issueCycles(a + b, m, a) }.sum
    bipartite.toDouble should be < 0.62 * triangular
  }

  it should "refuse a split outside 1 .. n-1" in {
    an[IllegalArgumentException] should be thrownBy Schedule.issueCycles(10, 4, 10)
    an[IllegalArgumentException] should be thrownBy StreamScheduleModel.run(10, 4, 2, 10)
  }

  it should "start up in readLatency cycles, the closed form" in {
    for ((m, n) <- cases if n >= 2; l <- latencies) withClue(s"m=$m n=$n readLatency=$l: ") {
      val p = AccelParams(m = m, capacity = 1024, memoryOutputStages = l - 2, arch = Arch.Stream)
      StreamScheduleModel.run(n, m, l).startupCycles.toLong shouldBe p.startupCycles(n)
    }
  }
}
