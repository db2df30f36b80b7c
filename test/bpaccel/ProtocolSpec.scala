package bpaccel

import chisel3._
import chiseltest._
import org.scalatest.flatspec.AnyFlatSpec

import scala.util.Random

/** Errors instead of silent truncation, and recovery after runs and resets, for both architectures. */
class ProtocolSpec extends AnyFlatSpec with Simulators with Checks {
  private val configurations = Seq(SharedConfigs.seedM3, SharedConfigs.streamM3)

  for (p <- configurations) {
    val arch = s"(${p.arch.name})"

    def withDut(body: (BroadPhaseAccel, AccelDriver) => Unit): Unit =
      onVerilator(p) { dut =>
        val drv = new AccelDriver(dut)
        drv.idleInputs()
        body(dut, drv)
      }

    def boxes(n: Int, seed: Int) = Box.Scenes.uniform(new Random(seed), n, p.keyWidth, 30, 10)

    "The info port" should s"report the configuration the C header describes $arch" in {
      withDut { (dut, _) =>
        dut.io.info.arch.expect(p.arch.id.U)
        dut.io.info.m.expect(p.m.U)
        dut.io.info.capacity.expect(p.capacity.U)
        dut.io.info.keyWidth.expect(p.keyWidth.U)
        dut.io.info.runOverheadCycles.expect(p.runOverheadCycles.U)
        dut.io.info.readLatency.expect(p.startupLatency.U)
      }
    }

    "A load beyond the capacity" should s"raise LoadOverflow at once and fail the next start without results $arch" in {
      withDut { (dut, drv) =>
        drv.load(boxes(p.capacity, 1))
        dut.io.status.error.expect(AccelError.None)
        dut.io.status.loaded.expect(p.capacity.U)
        drv.load(boxes(1, 2))
        dut.io.status.error.expect(AccelError.LoadOverflow)
        val out = drv.start(p.capacity)
        out.error shouldBe AccelError.code(AccelError.LoadOverflow)
        out.pairs shouldBe empty
        out.cycles shouldBe 0
        // The error does not stick: a correct run follows.
        val b = boxes(9, 3)
        checkRun(p, b, drv.run(b), consumerNeverStalls = true)
      }
    }

    "A start with n above the capacity" should s"fail with CountOverCapacity $arch" in {
      withDut { (_, drv) =>
        drv.load(boxes(p.capacity, 4))
        val out = drv.start(p.capacity + 1)
        out.error shouldBe AccelError.code(AccelError.CountOverCapacity)
        out.pairs shouldBe empty
      }
    }

    "A start with n above the boxes loaded" should s"fail with CountOverLoaded $arch" in {
      withDut { (_, drv) =>
        drv.load(boxes(5, 5))
        val out = drv.start(6)
        out.error shouldBe AccelError.code(AccelError.CountOverLoaded)
        out.pairs shouldBe empty
        out.hits shouldBe 0
      }
    }

    "A start with a split" should s"fail with ${if (p.bipartiteRuns) "SplitOutOfRange when the split is not below n" else "SplitUnsupported"}, without results $arch" in {
      withDut { (dut, drv) =>
        val b = boxes(7, 9)
        for (split <- if (p.bipartiteRuns) Seq(7, 8, p.capacity) else Seq(1, 3, 6)) withClue(s"split $split: ") {
          drv.load(b)
          val out = drv.start(7, split = split)
          out.error shouldBe AccelError.code(if (p.bipartiteRuns) AccelError.SplitOutOfRange else AccelError.SplitUnsupported)
          out.pairs shouldBe empty
          out.cycles shouldBe 0
        }
        dut.io.info.bipartiteRuns.expect(p.bipartiteRuns.B)
        // The error does not stick: a correct run follows.
        checkRun(p, b, drv.run(b), consumerNeverStalls = true)
      }
    }

    // The host always loads exactly n, but the protocol allows fewer: the
    // boxes after the first n must play no part. (Found by the whole-run
    // formal check at m = 2: the stream's window, filled from the loads,
    // held object n in lane 0 when n <= m.)
    "A start with n below the boxes loaded" should s"report exactly the pairs of the first n objects $arch" in {
      withDut { (_, drv) =>
        for (n <- 2 to p.m + 2; extra <- 1 to 3) withClue(s"n=$n, ${n + extra} loaded: ") {
          val b = boxes(n + extra, 100 * n + extra)
          drv.load(b)
          val out = drv.start(n)
          out.error shouldBe AccelError.code(AccelError.None)
          out.pairs.distinct.length shouldBe out.pairs.length
          out.pairs.toSet shouldBe Box.bruteForcePairs(b.take(n))
          out.hits shouldBe out.pairs.length.toLong
          out.issueCycles shouldBe Schedule.issueCycles(n, p.m)
          out.cycles shouldBe out.driverCycles
        }
      }
    }

    // A stream run of L < m + 1 loaded boxes starts d = m + 1 - L lanes up and
    // reports its beat bases moved down by d, modulo 2^indexWidth: with every
    // pair overlapping, each lane of such a run hits, so a decoder without the
    // modulo reports indices past n. (Random scenes of a few boxes rarely hit.)
    "A run of fewer than m + 2 objects" should s"report every pair when all boxes overlap, whatever was loaded $arch" in {
      withDut { (_, drv) =>
        val same = Box(Seq.fill(3)(BigInt(5)), Seq.fill(3)(BigInt(9)))
        for (n <- 2 to p.m + 1; loaded <- n to p.m + 2) withClue(s"n=$n, $loaded loaded: ") {
          drv.load(Seq.fill(loaded)(same))
          val out = drv.start(n)
          out.error shouldBe AccelError.code(AccelError.None)
          out.pairs.distinct.length shouldBe out.pairs.length
          out.pairs.toSet shouldBe Box.bruteForcePairs(Seq.fill(n)(same))
          out.hits shouldBe n * (n - 1) / 2
        }
      }
    }

    "Runs with fewer than two objects" should s"finish at once with no pairs and no error $arch" in {
      withDut { (_, drv) =>
        for (n <- Seq(0, 1)) {
          val out = drv.run(boxes(n, 6))
          out.error shouldBe AccelError.code(AccelError.None)
          out.pairs shouldBe empty
          out.cycles shouldBe 0
        }
      }
    }

    "The load-cycle counter" should s"count from the first box to the start, pauses included $arch" in {
      withDut { (_, drv) =>
        drv.load(boxes(3, 10))
        drv.idle(5) // the host pauses: the device still belongs to this run
        drv.load(boxes(2, 11))
        val out = drv.start(5)
        out.loadCycles shouldBe 3 + 5 + 2 + 1
        out.loadCycles shouldBe out.driverLoadCycles
        // A start with nothing loaded costs its own cycle only.
        drv.idle(4)
        drv.start(0).loadCycles shouldBe 1
      }
    }

    "Loading" should s"be refused while a run is busy $arch" in {
      withDut { (dut, drv) =>
        drv.load(boxes(16, 7))
        drv.pulseStart(16)
        dut.io.status.busy.expect(true.B)
        dut.io.load.ready.expect(false.B)
        dut.io.start.ready.expect(false.B)
      }
    }

    "A reset in the middle of a run" should s"leave an idle accelerator that runs the next scene exactly $arch" in {
      withDut { (dut, drv) =>
        drv.load(boxes(16, 8))
        drv.pulseStart(16)
        dut.io.result.ready.poke(true.B)
        dut.clock.step(7)
        dut.io.status.busy.expect(true.B)
        dut.reset.poke(true.B)
        dut.clock.step()
        dut.reset.poke(false.B)
        dut.io.result.ready.poke(false.B)
        dut.io.status.busy.expect(false.B)
        dut.io.status.done.expect(false.B)
        dut.io.status.loaded.expect(0.U)
        dut.io.result.valid.expect(false.B)
        val b = boxes(13, 9)
        checkRun(p, b, drv.run(b, c => c % 3 != 0), consumerNeverStalls = false)
      }
    }
  }
}
