package bpaccel

import chiseltest._
import org.scalatest.flatspec.AnyFlatSpec

import scala.util.Random

/** Every overlapping pair, exactly once, whatever the consumer does. */
class ResultSpec extends AnyFlatSpec with Simulators with Checks {

  /** Consumer ready patterns, from eager to very slow. */
  private def readyPatterns(rng: Random): Seq[(String, Int => Boolean)] = {
    val seed = rng.nextInt()
    Seq(
      "always ready"        -> (_ => true),
      "ready 1 cycle in 2"  -> (c => c % 2 == 0),
      "random 25%"          -> { val r = new Random(seed); _ => r.nextInt(4) == 0 },
      "bursts of 7 stalled" -> (c => c % 9 >= 7),
      "long stall first"    -> (c => c > 60)
    )
  }

  behavior of "The accelerator"

  private val backPressured = Seq(
    SharedConfigs.seedM1,
    AccelParams(m = 2, capacity = 16, arch = Arch.Seed),
    SharedConfigs.seedM3,
    AccelParams(m = 4, capacity = 32, arch = Arch.Seed),
    AccelParams(m = 5, capacity = 40, arch = Arch.Seed),
    SharedConfigs.seedM8,
    AccelParams(m = 1, capacity = 16, arch = Arch.Stream),
    SharedConfigs.streamM3,
    SharedConfigs.streamM8,
    AccelParams(m = 12, capacity = 48, arch = Arch.Stream) // two hit-count groups, one short
  )

  for (p <- backPressured; m = p.m; capacity = p.capacity)
    it should s"report exactly the brute-force pairs under any back-pressure (m=$m, ${p.arch.name})" in {
      onVerilator(p) { dut =>
        val drv = new AccelDriver(dut)
        drv.idleInputs()
        val rng        = new Random(100 + m)
        var sawStalls  = false
        for {
          (scene, boxes) <- Box.Scenes.all(rng, 2 + rng.nextInt(capacity - 1), p.keyWidth) :+
                              ("full capacity" -> Box.Scenes.uniform(rng, capacity, p.keyWidth, 50, 10))
          (pattern, ready) <- readyPatterns(rng)
        } withClue(s"m=$m scene '$scene' (n=${boxes.length}) consumer '$pattern': ") {
          val out = drv.run(boxes, ready)
          checkRun(p, boxes, out, consumerNeverStalls = pattern == "always ready")
          sawStalls ||= out.stallCycles > 0
        }
        withClue("no pattern ever back-pressured the sequencer, so stalls went untested: ") {
          sawStalls shouldBe true
        }
      }
    }

  it should "stop at its own check when the stream's look-ahead enables ignore back-pressure (mutant)" in {
    val p = AccelParams(m = 3, capacity = 25, arch = Arch.Stream, faults = Set(Fault.LookaheadIgnoresRoom))
    onVerilator(p) { dut =>
      val drv   = new AccelDriver(dut)
      drv.idleInputs()
      val boxes = Box.Scenes.uniform(new Random(5), 25, p.keyWidth, span = 20, maxExtent = 10)
      checkRun(p, boxes, drv.run(boxes), consumerNeverStalls = true) // no back-pressure: no difference
      intercept[ChiselAssertionError](drv.run(boxes, c => c > 60))
    }
  }

  for (stages <- Seq(0, 1, 3))
    it should s"report exactly the brute-force pairs with $stages memory output stages (m=3)" in {
      val p = AccelParams(m = 3, capacity = 24, memoryOutputStages = stages, arch = Arch.Seed)
      onVerilator(p) { dut =>
        val drv = new AccelDriver(dut)
        drv.idleInputs()
        val rng = new Random(30 + stages)
        for ((scene, boxes) <- Box.Scenes.all(rng, 24, p.keyWidth)) withClue(s"scene '$scene': ") {
          checkRun(p, boxes, drv.run(boxes, c => c % 5 != 2), consumerNeverStalls = false)
          checkRun(p, boxes, drv.run(boxes), consumerNeverStalls = true)
        }
      }
    }

  it should "work with narrow keys (8 bits) at the ends of their range" in {
    val p = AccelParams(m = 4, capacity = 32, keyWidth = 8, arch = Arch.Seed)
    onVerilator(p) { dut =>
      val drv = new AccelDriver(dut)
      drv.idleInputs()
      val rng = new Random(8)
      for ((scene, boxes) <- Box.Scenes.all(rng, 32, p.keyWidth)) withClue(s"scene '$scene': ") {
        checkRun(p, boxes, drv.run(boxes), consumerNeverStalls = true)
      }
    }
  }
}
