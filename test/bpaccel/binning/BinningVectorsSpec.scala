package bpaccel.binning

import java.nio.file.{Files, Paths}

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

/** The host's C++ model is checked against vectors this project commits
  * (BinningVectors); they must be what the cycle model says today, or the
  * C++ check would pass against a model that has moved on.
  */
class BinningVectorsSpec extends AnyFlatSpec with Matchers {
  "The committed host vectors" should "be what the cycle model writes today" in {
    val file = Paths.get(BinningVectors.committed)
    withClue(s"$file is stale, write it again with Test/runMain bpaccel.binning.BinningVectors: ") {
      Files.readString(file) shouldBe BinningVectors.render()
    }
  }
}
