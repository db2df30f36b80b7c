package bpaccel

import chiseltest._
import org.scalatest.flatspec.AnyFlatSpec

import scala.util.Random

/** The generated schedule against each architecture's golden model, cycle
  * by cycle and lane by lane, on Verilator: for the seed the sequencer's
  * addresses through the rotator, for the stream the object tags that travel
  * through the window and the A registers with the data.
  */
class ScheduleHardwareSpec extends AnyFlatSpec with Simulators with Checks {

  private def scheduleAllCounts(
    m: Int,
    counts: Int => Seq[Int],
    capacity: Int,
    arch: Arch = Arch.Seed,
    memoryStyle: MemoryStyle = MemoryStyle.Inferred
  ): Unit = {
    val p = AccelParams(m = m, capacity = capacity, debugPort = true, arch = arch, memoryStyle = memoryStyle)
    onVerilator(p) { dut =>
      val drv = new AccelDriver(dut)
      drv.idleInputs()
      val rng = new Random(m)
      // One simulator for many runs: each run also proves a new run after a finished one works.
      for (n <- counts(capacity)) withClue(s"m=$m n=$n: ") {
        val boxes = Box.Scenes.uniform(rng, n, p.keyWidth, span = 60, maxExtent = 12)
        val out   = drv.run(boxes)
        checkSchedule(p, n, out)
        checkRun(p, boxes, out, consumerNeverStalls = true)
      }
    }
  }

  behavior of "The hardware schedule"

  for (m <- 1 to 8)
    it should s"match the golden model for m=$m and every n up to the capacity" in {
      scheduleAllCounts(m, capacity => 0 to capacity, capacity = 5 * m)
    }

  for (m <- Seq(13, 16, 32))
    it should s"match the golden model for m=$m at small n, around multiples of m and at the capacity" in {
      scheduleAllCounts(
        m,
        capacity => (Seq(0, 1, 2, 3, m - 1, m, m + 1, 2 * m - 1, 2 * m, 2 * m + 1, capacity - 1, capacity)).distinct,
        capacity = 3 * m
      )
    }

  behavior of "The stream architecture's schedule"

  // Capacities shared with the bipartite tests below, so each m is one model (5m + 1, and 4m + 3 at m = 1).
  private def streamCapacity(m: Int): Int = (5 * m + 1).max(4 * m + 3)

  for (m <- Seq(1, 2, 3, 5, 8))
    it should s"match the stream golden model for m=$m and every n up to the capacity" in {
      scheduleAllCounts(m, capacity => 0 to capacity, capacity = streamCapacity(m), arch = Arch.Stream)
    }

  for ((m, capacity) <- Seq(13 -> 3 * 13, 16 -> (3 * 16 + 2)))
    it should s"match the stream golden model for m=$m at small n, around multiples of m and at the capacity" in {
      scheduleAllCounts(
        m,
        capacity => (Seq(0, 1, 2, 3, m - 1, m, m + 1, m + 2, 2 * m - 1, 2 * m, 2 * m + 1, 2 * m + 2, capacity - 1, capacity)).distinct,
        capacity = capacity,
        arch = Arch.Stream
      )
    }

  /** Bipartite runs of every n and split up to the capacity, on one simulator
    * (so a bipartite run after a triangular one and the reverse are covered too).
    */
  private def bipartiteAllSplits(m: Int, capacity: Int, counts: Seq[Int], memoryStyle: MemoryStyle): Unit = {
    val p = AccelParams(m = m, capacity = capacity, debugPort = true, arch = Arch.Stream, memoryStyle = memoryStyle)
    onVerilator(p) { dut =>
      val drv = new AccelDriver(dut)
      drv.idleInputs()
      val rng = new Random(100 + m)
      for (n <- counts; split <- 0 until n) withClue(s"m=$m n=$n split=$split: ") {
        val boxes = Box.Scenes.uniform(rng, n, p.keyWidth, span = 40, maxExtent = 12)
        val out   = drv.run(boxes, split = split)
        checkSchedule(p, n, out, split)
        checkRun(p, boxes, out, consumerNeverStalls = true, split = split)
      }
    }
  }

  behavior of "The stream architecture's bipartite runs"

  for (m <- Seq(1, 2, 3, 4))
    it should s"match the bipartite golden model for m=$m, every n up to 4m + 3 and every split" in {
      bipartiteAllSplits(m, capacity = streamCapacity(m), counts = 2 to 4 * m + 3, MemoryStyle.Inferred)
    }

  for (m <- Seq(7, 16))
    it should s"match the bipartite golden model for m=$m around block edges, every split" in {
      bipartiteAllSplits(m, capacity = 3 * m + 2, counts = Seq(2, m, m + 1, m + 2, 2 * m + 1, 3 * m + 2), MemoryStyle.Inferred)
    }

  it should "match the bipartite golden model with the output register inside the block RAM (m=3)" in {
    bipartiteAllSplits(3, capacity = streamCapacity(3), counts = 2 to 14, MemoryStyle.Ecp5OutputRegister)
  }

  behavior of "The schedule with the output register inside the block RAM (memory style ecp5-outreg)"

  // The same golden models and cycle formulas: the style moves a register, it adds none.
  // m = 3 (not a power of two) for both, and stream m = 8 as FPGA-built; kept to three for make test's time.
  for ((arch, m) <- Seq(Arch.Seed -> 3, Arch.Stream -> 3, Arch.Stream -> 8))
    it should s"match the ${arch.name} golden model for m=$m and every n up to the capacity" in {
      val capacity = if (arch == Arch.Seed) 5 * m else streamCapacity(m)
      scheduleAllCounts(m, capacity => 0 to capacity, capacity, arch, MemoryStyle.Ecp5OutputRegister)
    }
}
