package bpaccel

import java.util.concurrent.{ConcurrentHashMap, Semaphore}

import chisel3.Module
import chiseltest._
import chiseltest.internal.CachingAnnotation
import chiseltest.simulator.VerilatorBackendAnnotation
import firrtl2.options.TargetDirAnnotation
import org.scalatest.TestSuite

/** How the specs simulate the accelerator.
  *
  * Verilator simulates the emitted design itself and runs about a hundred
  * times faster than ChiselTest's default Scala simulator (measured here:
  * 0.04 s against 5.2 s for the same 120-cycle run at m = 8), so most specs use it;
  * `DefaultSimulatorSpec` keeps a smaller share on the default simulator.
  * Every Verilator test goes through [[VerilatorModels]], so a design is
  * compiled once per sbt run whichever specs use it.
  */
trait Simulators extends ChiselScalatestTester { this: TestSuite =>

  /** A test of the accelerator of `p` on Verilator, on the model every spec shares for `p`. */
  def onVerilator(p: AccelParams)(body: BroadPhaseAccel => Unit): Unit =
    onSharedVerilator(BroadPhaseAccel.topName, p)(new BroadPhaseAccel(p))(body)

  /** A test of any design on Verilator, compiled once per `(design, parameters)`:
    * `parameters` (usually the generator's case class) must determine the
    * design `dut` builds, since its text names the model's folder.
    */
  def onSharedVerilator[T <: Module](design: String, parameters: Any)(dut: => T)(body: T => Unit): Unit =
    VerilatorModels.withModel(design, parameters) { (dir, compiled) =>
      test(dut).withAnnotations(VerilatorModels.annotations(dir)) { c =>
        compiled()
        body(c)
      }
    }

  def onDefaultSimulator(p: AccelParams)(body: BroadPhaseAccel => Unit): Unit =
    test(new BroadPhaseAccel(p))(body)
}

/** Verilator models shared by all specs of one sbt run (they run as threads
  * of one forked JVM, build.sbt), one per design: each lives in
  * test_run_dir/verilator/<design>/<parameters>, and ChiselTest's cache
  * (CachingAnnotation) reuses it when the elaborated circuit is the same,
  * recompiling it when the sources changed. The first test of a design
  * compiles it while any other test of that design waits; once it runs,
  * all tests of the design run side by side on copies of the same library.
  */
object VerilatorModels {
  def annotations(dir: String) = Seq(VerilatorBackendAnnotation, CachingAnnotation, TargetDirAnnotation(dir))

  private final class Model {
    val firstUse        = new Semaphore(1)
    @volatile var built = false
  }
  private val models = new ConcurrentHashMap[String, Model]()

  /** The model's folder: the design's name, then its parameters as a file name. */
  def directory(design: String, parameters: Any): String =
    s"test_run_dir/verilator/$design/${parameters.toString.replaceAll("[^A-Za-z0-9_.-]+", "_")}"

  /** Runs `run(dir, compiled)`, which must call `compiled()` once the simulator has started. */
  def withModel(design: String, parameters: Any)(run: (String, () => Unit) => Unit): Unit = {
    val dir   = directory(design, parameters)
    val model = models.computeIfAbsent(dir, _ => new Model)
    if (model.built) run(dir, () => ())
    else {
      model.firstUse.acquire()
      var held = true
      def release(): Unit = if (held) { held = false; model.firstUse.release() }
      try {
        if (model.built) { release(); run(dir, () => ()) }
        else run(dir, () => { model.built = true; release() })
      } finally release()
    }
  }
}

/** Configurations several specs simulate, named once so that they share one model each. */
object SharedConfigs {
  val seedM1   = AccelParams(m = 1, capacity = 12, arch = Arch.Seed, batchCells = 8)
  val seedM3   = AccelParams(m = 3, capacity = 24, arch = Arch.Seed, batchCells = 8) // m not a power of two
  val seedM8   = AccelParams(m = 8, capacity = 64, arch = Arch.Seed, batchCells = 16)
  val streamM3 = AccelParams(m = 3, capacity = 25, arch = Arch.Stream, batchCells = 8) // capacity no multiple of m
  val streamM8 = AccelParams(m = 8, capacity = 64, arch = Arch.Stream, batchCells = 4)
}
