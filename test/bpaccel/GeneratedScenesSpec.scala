package bpaccel

import org.scalacheck.{Gen, Shrink}
import org.scalatest.exceptions.TestFailedException
import org.scalatest.flatspec.AnyFlatSpec
import org.scalatestplus.scalacheck.ScalaCheckPropertyChecks

import scala.util.Random

/** Scenes no one wrote by hand: random configurations, object counts up to
  * the capacity, adversarial key distributions and random consumer ready
  * patterns, checked against the brute-force pairs. A failure is shrunk to
  * fewer boxes and an always-ready consumer before it is reported.
  *
  * The configurations are drawn from a seed (BPACCEL_PROPERTY_SEED, fixed by
  * default so CI is repeatable; the spec prints the one it used). Each needs
  * a Verilator build, so a run draws a few.
  */
class GeneratedScenesSpec extends AnyFlatSpec with Simulators with Checks with ScalaCheckPropertyChecks {

  /** One run: the boxes, and a ready pattern (a seed and how often the consumer is ready). */
  case class Scenario(boxes: List[Box], readySeed: Long, readyPercent: Int) {
    def ready: Int => Boolean =
      if (readyPercent >= 100) _ => true
      else { val r = new Random(readySeed); _ => r.nextInt(100) < readyPercent }
    override def toString = s"n=${boxes.length}, ready ${readyPercent}% (seed $readySeed), boxes ${boxes.mkString(" ")}"
  }

  /** Key distributions that make exact cases likely: a tiny key space (touching
    * and identical boxes everywhere), clusters, keys at 0 and at the maximum,
    * zero-extent points, and a sparse spread.
    */
  private def boxGen(keyWidth: Int): Gen[Box] = {
    val top  = (BigInt(1) << keyWidth) - 1
    def key(lo: BigInt, hi: BigInt): Gen[BigInt] = Gen.choose(lo.toLong, hi.min(top).toLong).map(BigInt(_))
    def boxFrom(lo: Gen[BigInt], ext: Gen[BigInt]): Gen[Box] = for {
      l <- Gen.listOfN(3, lo)
      e <- Gen.listOfN(3, ext)
    } yield Box(l, l.zip(e).map { case (a, b) => (a + b).min(top) })
    Gen.frequency(
      3 -> boxFrom(key(0, 7), key(0, 3)),                     // tiny key space
      2 -> boxFrom(key(100, 140), key(0, 20)),                // a cluster
      2 -> boxFrom(Gen.oneOf(BigInt(0), top), Gen.oneOf(BigInt(0), top)), // the ends of the range
      1 -> boxFrom(key(0, 50), Gen.const(BigInt(0))),         // points
      1 -> boxFrom(key(0, top), key(0, top / 16))             // sparse
    )
  }

  private def scenarioGen(p: AccelParams): Gen[Scenario] = for {
    n       <- Gen.frequency(3 -> Gen.choose(0, 4 * p.m + 4).map(_.min(p.capacity)), 1 -> Gen.choose(0, p.capacity))
    boxes   <- Gen.listOfN(n, boxGen(p.keyWidth))
    seed    <- Gen.choose(0L, Long.MaxValue)
    percent <- Gen.oneOf(100, 100, 70, 30, 5)
  } yield Scenario(boxes, seed, percent)

  /** Fewer boxes first, then an always-ready consumer. */
  implicit val shrinkScenario: Shrink[Scenario] = Shrink.withLazyList { s =>
    Shrink.shrinkContainer[List, Box].shrink(s.boxes).map(b => s.copy(boxes = b)).to(LazyList) #:::
      (if (s.readyPercent < 100) LazyList(s.copy(readyPercent = 100)) else LazyList.empty)
  }

  /** Runs every generated scenario on one configuration, against `reference`. */
  private def check(p: AccelParams, scenarios: Int, reference: Seq[Box] => Set[(Int, Int)] = Box.bruteForcePairs(_)): Unit =
    onVerilator(p) { dut =>
      val drv = new AccelDriver(dut)
      drv.idleInputs()
      forAll(scenarioGen(p), MinSuccessful(org.scalactic.anyvals.PosInt.from(scenarios).get)) { s =>
        val out = drv.run(s.boxes, s.ready)
        out.error shouldBe AccelError.code(AccelError.None)
        out.pairs.distinct.length shouldBe out.pairs.length
        out.pairs.toSet shouldBe reference(s.boxes)
        out.hits shouldBe out.pairs.length.toLong
        out.issueCycles shouldBe Schedule.issueCycles(s.boxes.length, p.m)
      }
    }

  private val seed = sys.env.get("BPACCEL_PROPERTY_SEED").map(_.toLong).getOrElse(20261128L)
  private val configs = {
    val rng = new Random(seed)
    Seq.fill(3) {
      val m = 1 + rng.nextInt(7)
      AccelParams(m = m, capacity = m * (2 + rng.nextInt(5)), keyWidth = Seq(8, 16, 32)(rng.nextInt(3)), arch = Arch.Seed)
    }.distinct
  }
  info(s"configurations drawn from seed $seed (set BPACCEL_PROPERTY_SEED to draw others)")

  behavior of "The accelerator on generated scenes"

  for (p <- configs)
    it should s"report exactly the brute-force pairs (m=${p.m}, capacity=${p.capacity}, ${p.keyWidth}-bit keys)" in {
      check(p, scenarios = 40)
    }

  it should "find a planted disagreement and shrink it to a small scene" in {
    // The reference forgets pairs of identical boxes: the check must fail, and
    // shrinking must bring the scene down to the two boxes that show it.
    val p = AccelParams(m = 3, capacity = 12, keyWidth = 8, arch = Arch.Seed)
    val wrongReference: Seq[Box] => Set[(Int, Int)] =
      boxes => Box.bruteForcePairs(boxes).filterNot { case (i, j) => boxes(i) == boxes(j) }
    val failure = intercept[TestFailedException](check(p, scenarios = 200, wrongReference))
    val shrunk  = "n=(\\d+)".r.findFirstMatchIn(failure.getMessage).map(_.group(1).toInt)
    withClue(failure.getMessage) { shrunk.getOrElse(Int.MaxValue) should be <= 2 }
  }
}
