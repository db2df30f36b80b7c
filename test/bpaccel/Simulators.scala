package bpaccel

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
  * `DefaultSimulatorSpec` keeps a smaller share on the default simulator. A
  * compiled model is cached per suite and configuration, so several tests of
  * one configuration build it once.
  */
trait Simulators extends ChiselScalatestTester { this: TestSuite =>

  def onVerilator(p: AccelParams)(body: BroadPhaseAccel => Unit): Unit = {
    val dir = s"test_run_dir/verilator/${getClass.getSimpleName}/${CHeader.fingerprint(p).replaceAll("[=,]", "_")}"
    test(new BroadPhaseAccel(p))
      .withAnnotations(Seq(VerilatorBackendAnnotation, CachingAnnotation, TargetDirAnnotation(dir)))(body)
  }

  def onDefaultSimulator(p: AccelParams)(body: BroadPhaseAccel => Unit): Unit =
    test(new BroadPhaseAccel(p))(body)
}
