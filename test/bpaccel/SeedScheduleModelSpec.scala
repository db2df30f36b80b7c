package bpaccel

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import scala.util.Random

class SeedScheduleModelSpec extends AnyFlatSpec with Matchers {

  private def allPairs(n: Int): Seq[(Int, Int)] = for (i <- 0 until n; j <- i + 1 until n) yield (i, j)

  /** Small exhaustive grid plus larger and random cases. */
  private val cases: Seq[(Int, Int)] = {
    val small  = for (m <- 1 to 16; n <- 0 to 4 * m + 4) yield (m, n)
    val larger = for (m <- Seq(1, 2, 7, 8, 13, 16, 32, 64); n <- Seq(100, 257, 512, 513)) yield (m, n)
    val rng    = new Random(2)
    val random = Seq.fill(40)((1 + rng.nextInt(40), rng.nextInt(400)))
    small ++ larger ++ random
  }

  "The seed's schedule (selectors mod m)" should "test every pair i < j exactly once and nothing else" in {
    for ((m, n) <- cases) withClue(s"m=$m n=$n: ") {
      val tested = SeedScheduleModel.testedPairs(n, m, selectorModulus = m)
      all(tested.map { case (i, j) => i < j }) shouldBe true
      all(tested.map { case (_, j) => j < n }) shouldBe true
      tested.sorted shouldBe allPairs(n) // same multiset: no miss, no repeat
    }
  }

  it should "take exactly the documented number of cycles" in {
    for ((m, n) <- cases) withClue(s"m=$m n=$n: ") {
      SeedScheduleModel.cycles(n, m).length.toLong shouldBe Schedule.issueCycles(n, m)
    }
  }

  it should "keep each block's first lane busy on every cycle" in {
    // Lane 0 pairs object b*m with every later object, so no cycle of a block is wasted on it.
    for ((m, n) <- cases if n >= 2) withClue(s"m=$m n=$n: ") {
      all(SeedScheduleModel.cycles(n, m).map(_.head.isDefined)) shouldBe true
    }
  }

  "The seed's text taken literally (selectors mod m - 1)" should "miss or repeat pairs for every m >= 2" in {
    // Settles the seed's "incremented by 1 mod m - 1": with m lanes the B window
    // rotates through m memories, so the selectors must count mod m.
    for (m <- 2 to 16) withClue(s"m=$m: ") {
      val n = 3 * m
      SeedScheduleModel.testedPairs(n, m, selectorModulus = m - 1).sorted should not be allPairs(n)
    }
  }

  "Schedule.issueCycles" should "equal the sum over blocks of (n - 1 - b*m)" in {
    def plainSum(n: Long, m: Int): Long =
      if (n < 2) 0 else (0L to (n - 2) / m).map(b => n - 1 - b * m).sum
    for (m <- 1 to 70; n <- (0L to 300L) ++ Seq(4095L, 4096L, 4097L, 100000L)) withClue(s"m=$m n=$n: ") {
      Schedule.issueCycles(n, m) shouldBe plainSum(n, m)
    }
  }

  it should "not overflow for a million objects" in {
    // n(n-1)/2 pairs over m lanes, plus the tail of each block: between the two bounds.
    val n = 1000000L
    for (m <- Seq(1, 16, 64)) {
      val c = Schedule.issueCycles(n, m)
      c should be >= (n * (n - 1) / 2) / m
      c should be <= (n * (n - 1) / 2) / m + n
    }
  }
}
