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

  it should "start up in readLatency cycles, the closed form" in {
    for ((m, n) <- cases if n >= 2; l <- latencies) withClue(s"m=$m n=$n readLatency=$l: ") {
      val p = AccelParams(m = m, capacity = 1024, memoryOutputStages = l - 2, arch = Arch.Stream)
      StreamScheduleModel.run(n, m, l).startupCycles.toLong shouldBe p.startupCycles(n)
    }
  }
}
