package bpaccel

import java.io.ByteArrayOutputStream

import chiseltest._
import chiseltest.formal._
import firrtl2.options.TargetDirAnnotation
import org.scalatest.Tag
import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

/** Deep formal checks, left out of `sbt test` (see build.sbt) and run by `make formal-long`. */
object FormalLong extends Tag("bpaccel.FormalLong")

/** Small configurations the solver can explore from reset, and how deep. */
object FormalConfigs {
  /** Narrow keys and counters and the shallowest legal result queue keep the
    * solver fast and make a full queue reachable in a short run; no memory
    * output registers, so a run starts one cycle after its start.
    */
  def params(arch: Arch, m: Int, capacity: Int, keyWidth: Int = 1): AccelParams = {
    val p = AccelParams(
      m = m,
      capacity = capacity,
      keyWidth = keyWidth,
      memoryOutputStages = 0,
      debugPort = true,
      arch = arch,
      counterWidth = 4
    )
    p.copy(resultQueueDepth = p.pipelineLatency + 3)
  }

  /** Cycles from reset to `done` of a run of n objects whose consumer never
    * stalls: the reset cycle, n loads, the start, then the startup (from the
    * schedule's golden model), the issue cycles and the drain.
    */
  def runCycles(p: AccelParams, n: Int): Int = {
    val startup = p.arch match {
      case Arch.Stream => StreamScheduleModel.run(n, p.m, p.readLatency).startupCycles
      case Arch.Seed   => 0
    }
    1 + n + 1 + startup + Schedule.issueCycles(n, p.m).toInt + p.runOverheadCycles
  }
}

/** Bounded model checks of the accelerator with ChiselTest: every property of
  * [[FormalHarness]] holds in every behaviour of the first k cycles after
  * reset (ChiselTest 6.0.0 has no induction), with boxes, counts, load/start
  * timing and the consumer's `ready` all free.
  *
  * Solvers: [[FormalSolver]] (Yices 2 proves, z3 refutes; docs/verification.md).
  *
  * The proofs are [[FormalSpec]]; each property's mutant, the same check on
  * a design with one deliberate bug ([[Fault]]) that must fail with that
  * property's message, is in [[FormalMutantSpec]], a suite of its own so the
  * two run side by side.
  */
trait FormalChecks extends ChiselScalatestTester with Formal with Matchers { this: AnyFlatSpec =>
  private def dir(name: String) = TargetDirAnnotation(s"test_run_dir/formal/$name")

  private def timed[T](body: => T): (T, Double) = {
    val t0 = System.nanoTime()
    val r  = body
    (r, (System.nanoTime() - t0) / 1e9)
  }

  def prove(name: String, p: AccelParams, depth: Int, properties: Set[Property] = Property.all.toSet): Unit = {
    val (_, s) = timed(verify(new FormalHarness(p, properties), Seq(BoundedCheck(depth), FormalSolver.prover, dir(name))))
    info(f"${p.arch.name} m=${p.m} capacity=${p.capacity}: no violation within $depth cycles of reset ($s%.1f s)")
  }

  /** Runs the check on a mutant; it must fail, and the replayed counterexample
    * must trip `property` (the only monitor turned on; the design's own
    * assertions stay on too, so the message is what tells them apart).
    */
  def refute(fault: Fault, property: Property, p: AccelParams, depth: Int): Unit = {
    val printed = new ByteArrayOutputStream()
    val (e, s) = timed(Console.withOut(printed) {
      intercept[FailedBoundedCheckException] {
        FormalSolver.refuting { engine =>
          verify(
            new FormalHarness(p.copy(faults = Set(fault)), Set(property)),
            Seq(BoundedCheck(depth), engine, dir(s"mutant-${fault.toString}"))
          )
        }
      }
    })
    val replay = printed.toString
    withClue(s"replay of the counterexample:\n$replay\n") {
      caughtBy(property).exists(replay.contains) shouldBe true
    }
    info(f"${fault.description}: caught by ${property.name} ${e.failAt} steps after reset ($s%.1f s)")
  }

  /** What a failure of a property group prints: its monitor's messages, and the
    * design's own assertion of the same guarantee, which may fire first.
    */
  private def caughtBy(property: Property): Seq[String] = property match {
    case Property.ExactlyOnce => Seq(s"[${property.name}]", BroadPhaseAccel.ResultQueueOverflow)
    case other                => Seq(s"[${other.name}]")
  }
}

/** The proofs: whole runs of the smallest configurations, and the first cycles of larger ones. */
class FormalSpec extends AnyFlatSpec with FormalChecks {
  import FormalConfigs._

  // ---- proofs: a whole run of n = capacity objects without stalls, then two
  // cycles in which done must stay. k counts cycles after the reset cycle.
  // The split is free: a bipartite run of n objects takes at most the
  // triangular run's cycles (fewer blocks, none longer), so k covers it too.
  // `sbt test` proves those that take seconds; `make formal-long` the others.
  private def wholeRun(m: Int, c: Int): (Int, Int, Int) = (m, c, runCycles(params(Arch.Stream, m, c), c) - 1 + 2)
  private val quick = Seq(wholeRun(1, 2))
  private val long  = Seq(wholeRun(2, 3), wholeRun(1, 3), wholeRun(1, 4), wholeRun(3, 4), wholeRun(4, 5))

  behavior of "the stream architecture, bounded from reset"

  for ((m, c, k) <- quick)
    it should s"keep every property for m=$m, capacity=$c over a whole run ($k cycles)" in {
      prove(s"stream-m$m-c$c-k$k", params(Arch.Stream, m, c), k)
    }

  // m = 2, capacity 3, up to the end of a whole run of two objects (its run
  // of three, four cycles longer, takes three times as long: make formal-long).
  it should s"keep every property for m=2, capacity=3 over a whole run of two objects (${runCycles(params(Arch.Stream, 2, 3), 2) - 1} cycles)" in {
    val k = runCycles(params(Arch.Stream, 2, 3), 2) - 1
    prove(s"stream-m2-c3-k$k", params(Arch.Stream, 2, 3), k)
  }

  for ((m, c, k) <- long)
    it should s"keep every property for m=$m, capacity=$c over a whole run ($k cycles)" taggedAs FormalLong in {
      prove(s"stream-m$m-c$c-k$k", params(Arch.Stream, m, c), k)
    }

  // The first 5 cycles for m = 3 and 4 (capacity m + 1: one block and its
  // successor's first object), in seconds: loads in any order, error and
  // short starts and the start of a run, with m lanes. Their whole runs are
  // in make formal-long.
  for (m <- 3 to 4)
    it should s"keep every property for m=$m, capacity=${m + 1} over 5 cycles" in {
      prove(s"stream-m$m-c${m + 1}-k5", params(Arch.Stream, m, m + 1), 5)
    }

  behavior of "the seed architecture"

  private val combinedPortMessage = "Combined read/write ports are currently not supported"
  private def causes(e: Throwable): Seq[Throwable] = Iterator.iterate(e)(_.getCause).takeWhile(_ != null).take(20).toSeq

  // The seed's memories used to have one combined read/write port each, which
  // ChiselTest's formal backend rejects; they now have separate ports. The
  // cancel stays for a generator change that brings one back.
  private def proveSeed(name: String, depth: Int): Unit = {
    val p = params(Arch.Seed, 1, 2)
    try prove(name, p, depth)
    catch {
      case e: Throwable if causes(e).exists(c => Option(c.getMessage).exists(_.contains(combinedPortMessage))) =>
        cancel(
          "ChiselTest's formal backend rejects the seed architecture's memories (one combined read/write " +
            s"port each): \"$combinedPortMessage\""
        )
    }
  }

  it should "keep every property for m=1, capacity=2 over a whole run" in {
    val p = params(Arch.Seed, 1, 2)
    proveSeed("seed-m1-c2", runCycles(p, 2) - 1 + 2)
  }
}

/** Each property fails on a design with one deliberate bug. */
class FormalMutantSpec extends AnyFlatSpec with FormalChecks {
  import FormalConfigs._

  behavior of "each property on a mutant"

  // fault, the property that must catch it, m, capacity, depth (the check stops at the first failure)
  private val quickMutants: Seq[(Fault, Property, Int, Int, Int)] = Seq(
    (Fault.DoneClearedByLoad, Property.Done, 1, 2, 12),
    (Fault.ErrorStartLaunches, Property.ErrorStart, 1, 2, 12),
    (Fault.StrictCompare, Property.Pairs, 1, 2, 12),
    (Fault.DropBeatWhenNotReady, Property.ExactlyOnce, 1, 2, 12),
    (Fault.RepeatLastBeat, Property.Lanes, 1, 2, 12),
    (Fault.DoneBeforeQueueEmpty, Property.Done, 1, 2, 16),
    (Fault.LaneMaskOneTooWide, Property.Lanes, 2, 3, 16),
    (Fault.SkipSecondBlockAtMPlus2, Property.Pairs, 1, 3, 16),
    (Fault.HeadCopyOffByOne, Property.Lanes, 2, 3, 12),
    (Fault.ShortRunBasesNotMoved, Property.ExactlyOnce, 2, 3, 12),
    (Fault.BipartiteALanesUnmasked, Property.Lanes, 2, 3, 14)
  )
  private val longMutants: Seq[(Fault, Property, Int, Int, Int)] = Seq(
    (Fault.CreditOneTooMany, Property.ExactlyOnce, 1, 4, 24)
  )
  for ((fault, property, m, c, k) <- quickMutants)
    it should s"fail ${property.name} on a design where ${fault.description}" in {
      refute(fault, property, params(Arch.Stream, m, c), k)
    }
  for ((fault, property, m, c, k) <- longMutants)
    it should s"fail ${property.name} on a design where ${fault.description}" taggedAs FormalLong in {
      refute(fault, property, params(Arch.Stream, m, c), k)
    }
}
