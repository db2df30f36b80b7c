package bpaccel

import scala.sys.process.Process
import scala.util.Try

import chiseltest.formal.backends.{FormalEngineAnnotation, Yices2Engine, Z3EngineAnnotation}

/** The SMT solvers of the bounded model checks, installed pinned into
  * build/formal-tools by scripts/deps.sh (build.sbt puts it first on the
  * tests' PATH).
  *
  * Checks run on Yices 2, which answers this project's proofs two to three
  * times faster than z3 and finds the mutants' counterexamples three to
  * thirty times faster. A refutation's counterexample is replayed, and for
  * some of them Yices 2.6.5 answers the model query in a form ChiselTest
  * 6.0.0 does not read back ("did not reply to (get-value ...)"): those run
  * again on z3, which must then find the violation itself.
  * BPACCEL_FORMAL_SOLVER=z3 runs every check on z3, as a second opinion.
  * Debian's z3 4.8.12 stalls parsing ChiselTest's encoding of these designs,
  * hence the pinned one.
  */
object FormalSolver {
  private final case class Solver(annotation: FormalEngineAnnotation, command: String,
                                  version: scala.util.matching.Regex, minimum: (Int, Int)) {
    /** The solver on the tests' PATH, checked once: an old one would not fail but take hours. */
    lazy val checked: FormalEngineAnnotation = {
      val out   = Try(Process(Seq(command, "--version")).!!.trim).getOrElse(s"no $command on PATH")
      val found = version.findFirstMatchIn(out).map(m => (m.group(1).toInt, m.group(2).toInt))
      val (major, minor) = minimum
      assert(
        found.exists { case (a, b) => a > major || (a == major && b >= minor) },
        s"the formal checks need $command $major.$minor or later (run make deps, which installs it into " +
          s"build/formal-tools); found: $out"
      )
      annotation
    }
  }

  private val z3    = Solver(Z3EngineAnnotation, "z3", """Z3 version (\d+)\.(\d+)""".r, (4, 13))
  private val yices = Solver(Yices2Engine.annotation, "yices-smt2", """Yices (\d+)\.(\d+)""".r, (2, 6))

  /** The engine of the checks that must find no violation. */
  def prover: FormalEngineAnnotation = sys.env.getOrElse("BPACCEL_FORMAL_SOLVER", "yices") match {
    case "yices" => yices.checked
    case "z3"    => z3.checked
    case other   => throw new IllegalArgumentException(s"BPACCEL_FORMAL_SOLVER=$other: expected yices or z3")
  }

  /** Runs `check`, a check that must fail with a counterexample to replay, on
    * the prover's solver; if ChiselTest cannot read that solver's model back,
    * on z3.
    */
  def refuting[T](check: FormalEngineAnnotation => T): T = {
    val first = prover
    try check(first)
    catch {
      case e: RuntimeException if first != z3.checked && unreadableModel(e) => check(z3.checked)
    }
  }

  private def unreadableModel(e: RuntimeException): Boolean =
    Option(e.getMessage).exists(_.contains("did not reply to (get-value"))
}
