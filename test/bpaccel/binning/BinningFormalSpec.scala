package bpaccel.binning

import java.io.ByteArrayOutputStream

import chisel3.Module
import chiseltest._
import chiseltest.formal._
import firrtl2.options.TargetDirAnnotation
import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import bpaccel.{FormalLong, FormalSolver}
import chiseltest.formal.backends.FormalEngineAnnotation

/** Formal checks of the binning device: bounded model checking from reset
  * with bpaccel.FormalSolver (as bpaccel.FormalSpec), every input free, in three families: a
  * group's schedule, the output path, the whole core. `make test` runs a
  * shallow proof of each family and the schedule's mutants;
  * `make formal-long` (tag FormalLong) the deeper proofs, over whole runs,
  * and the mutants of the output path and of the core. Each property fails,
  * as it must, on a design with the bug it is there to catch ([[BinningFault]]).
  */
class BinningFormalSpec extends AnyFlatSpec with ChiselScalatestTester with Formal with Matchers {
  /** g lanes, 1-bit offsets, `entries` positions, no memory output registers, queues of three: a
    * queue's memory of one or two rows has an address of one bit or none, and a solver may describe such a
    * memory in a counterexample as a lambda, "(lambda ((x!1 Bool)) x!1)", which ChiselTest cannot
    * read back ("TODO implement parsing of SMT solver response").
    */
  def small(g: Int, entries: Int, pairsPerBeat: Int = 1): BinningParams = BinningParams(
    groupBits = Seq(1, 1, 1), lanesPerGroup = g, keyWidth = 2, cellBits = 1, boxCapacity = entries.max(3),
    groupCapacity = entries, intakeBoxes = 1, pairsPerBeat = pairsPerBeat, memoryOutputStages = 0, laneQueueDepth = 3,
    maskQueueDepth = 3, cellQueueDepth = 3, hitQueueDepth = 3, mergeQueueDepth = 3, counterWidth = 6)

  private def timed[T](body: => T): (T, Double) = {
    val t0 = System.nanoTime(); val r = body; (r, (System.nanoTime() - t0) / 1e9)
  }
  private def annotations(name: String, depth: Int, engine: FormalEngineAnnotation) =
    Seq(BoundedCheck(depth), engine, TargetDirAnnotation(s"test_run_dir/binning-formal/$name"))

  def prove(name: String, harness: => Module, depth: Int): Unit = {
    val (_, s) = timed(verify(harness, annotations(name, depth, FormalSolver.prover)))
    info(f"no violation within $depth cycles of reset ($s%.1f s)")
  }

  /** The check must fail on the mutant, and its replayed counterexample must name `property`. */
  def refute(name: String, fault: BinningFault, property: BinProperty, harness: => Module, depth: Int): Unit = {
    val printed = new ByteArrayOutputStream()
    val (e, s) = timed(Console.withOut(printed) {
      intercept[FailedBoundedCheckException] {
        FormalSolver.refuting(engine => verify(harness, annotations(s"mutant-$name", depth, engine)))
      }
    })
    withClue(s"replay of the counterexample:\n$printed\n") { printed.toString should include(s"[${property.name}]") }
    info(f"${fault.description}: caught by ${property.name} ${e.failAt} steps after reset ($s%.1f s)")
  }

  private def engine(p: BinningParams) = new EngineFormalHarness(p)

  behavior of "a group's schedule (reader, lanes, serializer) with free cells and entries"

  // Depths cover a whole run: one cell of three in two blocks (g = 1, every pair out by step 13;
  // `make test`), or two cells of two back to back (g = 2, by step 14; `make formal-long`).
  it should "hand out exactly the pairs its cells owe, each once (g = 1, 3 positions, 15 cycles)" in {
    prove("engine-g1-e3-k15", engine(small(1, 3)), 15)
  }
  it should "hand out exactly the pairs its cells owe, each once (g = 2, 4 positions, 16 cycles)" taggedAs FormalLong in {
    prove("engine-g2-e4-k16", engine(small(2, 4)), 16)
  }

  behavior of "each property of a group's schedule on a mutant"

  // (fault, property, g, positions, depth): each takes Yices a few seconds.
  private val engineMutants: Seq[(BinningFault, BinProperty, Int, Int, Int)] = Seq(
    (BinningFault.NoExactlyOnceRule, BinProperty.Pairs, 1, 2, 11),
    (BinningFault.StrictCompare, BinProperty.Complete, 1, 3, 15),
    (BinningFault.LaneMaskOneTooWide, BinProperty.Pairs, 2, 4, 16),
    (BinningFault.SerializerDropsBeat, BinProperty.Complete, 2, 4, 16)
  )
  for ((fault, property, g, e, k) <- engineMutants)
    it should s"fail ${property.name} where ${fault.description}" in {
      refute(fault.toString, fault, property, engine(small(g, e).copy(faults = Set(fault))), k)
    }

  behavior of "the output path (serializers, merge) with free hits and consumer"

  def outputConfig(faults: Set[BinningFault] = Set.empty): BinningParams =
    small(1, 2, pairsPerBeat = 2).copy(boxCapacity = 16, faults = faults)

  it should "hand out every pair once, each group's in order (g = 1, P = 2, 5 cycles)" in {
    prove("output-k5", new OutputFormalHarness(outputConfig()), 5)
  }
  it should "hand out every pair once, each group's in order (g = 1, P = 2, 8 cycles)" taggedAs FormalLong in {
    prove("output-k8", new OutputFormalHarness(outputConfig()), 8)
  }
  // z3 alone spent over three minutes on it without an answer: make formal-long.
  it should s"fail delivery where ${BinningFault.ClusterTakesWhenFull.description}" taggedAs FormalLong in {
    refute("ClusterTakesWhenFull", BinningFault.ClusterTakesWhenFull, BinProperty.Delivery,
      new OutputFormalHarness(outputConfig(Set(BinningFault.ClusterTakesWhenFull))), 8)
  }

  behavior of "the whole core (G = 8, 3 boxes), over its intake and error frames"

  it should "name each frame's first error and count its boxes and pairs (6 cycles)" in {
    prove("core-k6", new BinningFormalHarness(small(1, 2)), 6)
  }
  it should "name each frame's first error and count its boxes and pairs (10 cycles)" taggedAs FormalLong in {
    prove("core-k10", new BinningFormalHarness(small(1, 2)), 10)
  }
  // z3 alone spent over a minute on the first without an answer: make formal-long.
  for ((fault, property) <- Seq(BinningFault.OutOfGridOffByOne -> BinProperty.Errors, BinningFault.ReceivedCountsOffers -> BinProperty.Summary))
    it should s"fail ${property.name} where ${fault.description}" taggedAs FormalLong in {
      refute(fault.toString, fault, property, new BinningFormalHarness(small(1, 2).copy(faults = Set(fault))), 10)
    }
}
