package bpaccel

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

class EmitAllSpec extends AnyFlatSpec with Matchers {
  "EmitAll" should "split its arguments into one command per emitter at each +, dropping empty ones" in {
    EmitAll.commands(Seq("EmitShell", "--m", "8", "+", "EmitBinning", "--params-only", "+")) shouldBe
      Seq(Seq("EmitShell", "--m", "8"), Seq("EmitBinning", "--params-only"))
    EmitAll.commands(Seq("+", "+")) shouldBe empty
    EmitAll.commands(Nil) shouldBe empty
  }
}
