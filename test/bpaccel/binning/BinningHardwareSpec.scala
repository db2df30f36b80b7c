package bpaccel.binning

import scala.util.Random

import org.scalatest.flatspec.AnyFlatSpec

import bpaccel.MemoryStyle

/** The core on Verilator against the cycle model, event by event, and its
  * pairs against brute force: many frames per compiled configuration.
  */
class BinningHardwareSpec extends AnyFlatSpec with BinningSimulators with BinningChecks {

  /** G = 8, two lanes, two boxes a cycle, two pairs a beat. */
  val small = BinningParams(groupBits = Seq(1, 1, 1), lanesPerGroup = 2, keyWidth = 7, cellBits = 3, boxCapacity = 128,
    groupCapacity = 48, intakeBoxes = 2, pairsPerBeat = 2, memoryOutputStages = 1, hitQueueDepth = 4, debugPort = true)

  behavior of "The binning core"

  it should "match the cycle model event by event and report each pair once" in {
    onVerilator(small) { (dut, d) =>
      val rng = new Random(7)
      var frames, errors = 0
      for (round <- 0 until 30) {
        val (shift, dims) = BinScenes.grid(rng, small)
        val n = Seq(0, 1, 2, 3, 5, 17, 40, 90)(round % 8)
        for ((name, boxes) <- BinScenes.all(rng, n, shift, dims)) withClue(s"frame $frames ($name, shift $shift, dims $dims, n $n): ") {
          val f = BinFrame(boxes, shift, dims)
          val model = BinningCycleModel.run(small, f)
          val out = d.run(f).get
          checkAgainstModel(small, out, model, debug = true)
          if (model.error == BinningErrorCode.None) checkPairs(f, out) else { out.beats shouldBe empty; errors += 1 }
          frames += 1
        }
      }
      info(s"$frames frames ($errors with GROUP_OVERFLOW)")
    }
  }
}
