package bpaccel

import org.scalatest.flatspec.AnyFlatSpec

import scala.util.Random

/** A share of the checks on ChiselTest's default simulator, which interprets
  * the circuit rather than the emitted Verilog, so the two views agree.
  */
class DefaultSimulatorSpec extends AnyFlatSpec with Simulators with Checks {
  "On the default simulator, the accelerator" should "follow the golden schedule and report exact pairs (m=3)" in {
    val p = AccelParams(m = 3, capacity = 12, debugPort = true, arch = Arch.Seed)
    onDefaultSimulator(p) { dut =>
      val drv = new AccelDriver(dut)
      drv.idleInputs()
      val rng = new Random(3)
      for (n <- 0 to p.capacity) withClue(s"n=$n: ") {
        val boxes = Box.Scenes.uniform(rng, n, p.keyWidth, span = 40, maxExtent = 12)
        val out   = drv.run(boxes, c => c % 4 != 1)
        checkSchedule(p, n, out)
        checkRun(p, boxes, out, consumerNeverStalls = false)
      }
    }
  }
}
