package bpaccel.binning

import chisel3._
import chiseltest._
import chiseltest.internal.CachingAnnotation
import chiseltest.simulator.VerilatorBackendAnnotation
import firrtl2.options.TargetDirAnnotation
import org.scalatest.Assertions.fail
import org.scalatest.TestSuite

import bpaccel.Box

/** What one frame returned, as the shell would see it, with the debug probes. */
case class FrameOutcome(
  beats: Vector[BinningCycleModel.BeatAt],   // io.pairs handshakes, cycle 0 = the header's
  summaryCycle: Long,                        // first cycle the summary was valid
  error: Int,
  detail: Long,
  records: Long,
  boxes: Long,
  entries: Long,
  maxGroupEntries: Long,
  cycles: Long,
  intakeCycles: Long,
  issueCycles: Long,
  stallCycles: Long,
  writes: Vector[BinningCycleModel.WriteAt], // debug port only
  issues: Vector[Vector[(Long, Vector[Option[(Int, Int, Boolean)]])]] // per group: (cycle at the AND stage, lanes)
) {
  def pairs: Seq[(Int, Int)] = beats.flatMap(_.pairs)
}

/** Runs frames through a [[BinningCore]], one clock at a time. */
class BinningDriver(dut: BinningCore, maxCycles: Long = 400000) {
  private val p = dut.p
  dut.clock.setTimeout(0)

  def idleInputs(): Unit = {
    dut.io.frame.valid.poke(false.B)
    dut.io.boxes.valid.poke(false.B)
    dut.io.abort.poke(false.B)
    dut.io.pairs.ready.poke(false.B)
    dut.io.summary.ready.poke(false.B)
  }

  /** Steps until the core takes a header (after a reset or abort it first clears its tables). */
  def waitReady(limit: Int = p.localCells + 10): Int = {
    var n = 0
    while (!dut.io.frame.ready.peek().litToBoolean) {
      dut.clock.step(); n += 1
      if (n > limit) fail(s"frame.ready stayed low for $limit cycles")
    }
    n
  }

  private def pokeBeat(boxes: Seq[Box], last: Boolean): Unit = {
    for (l <- 0 until p.intakeBoxes) {
      val lane = dut.io.boxes.bits.boxes(l)
      lane.valid.poke((l < boxes.length).B)
      val b = boxes.lift(l).getOrElse(Box(Seq.fill(3)(BigInt(0)), Seq.fill(3)(BigInt(0))))
      for (a <- 0 until 3) {
        lane.bits.min(a).poke(b.min(a).U(p.keyWidth.W))
        lane.bits.max(a).poke(b.max(a).U(p.keyWidth.W))
      }
    }
    dut.io.boxes.bits.last.poke(last.B)
  }

  /** Sends the frame and plays the shell until the summary is taken. `abortAt`: assert abort in
    * that cycle instead (the frame then has no summary: None).
    */
  def run(
    f: BinFrame,
    ready: Long => Boolean = _ => true,
    offer: Long => Boolean = _ => true,
    layout: Option[Seq[Int]] = None,
    abortAt: Option[Long] = None
  ): Option[FrameOutcome] = {
    waitReady()
    val beatsIn = BinningCycleModel.beatsOf(f.boxes.length, p.intakeBoxes, layout)
    dut.io.frame.valid.poke(true.B)
    dut.io.frame.bits.n.poke(f.n.U)
    dut.io.frame.bits.shift.poke(f.shift.U)
    for (a <- 0 until 3) dut.io.frame.bits.dims(a).poke(f.dims(a).U)
    val beats  = Vector.newBuilder[BinningCycleModel.BeatAt]
    val writes = Vector.newBuilder[BinningCycleModel.WriteAt]
    val issues = Array.fill(p.groups)(Vector.newBuilder[(Long, Vector[Option[(Int, Int, Boolean)]])])
    var next = 0
    var t = 0L
    var summary: Option[FrameOutcome] = None
    while (summary.isEmpty) {
      if (t > maxCycles) fail(s"the frame did not end within $maxCycles cycles")
      if (t == 1) dut.io.frame.valid.poke(false.B)
      if (abortAt.contains(t)) {
        dut.io.abort.poke(true.B)
        dut.io.boxes.valid.poke(false.B)
        dut.io.pairs.valid.expect(false.B)
        dut.io.summary.valid.expect(false.B)
        dut.clock.step()
        dut.io.abort.poke(false.B)
        return None
      }
      val offering = t >= 1 && next < beatsIn.length && offer(t)
      dut.io.boxes.valid.poke(offering.B)
      if (offering) pokeBeat(beatsIn(next).map(f.boxes), next == beatsIn.length - 1)
      val r = ready(t)
      dut.io.pairs.ready.poke(r.B)
      dut.io.summary.ready.poke(true.B)
      if (t == 0 && !dut.io.frame.ready.peek().litToBoolean) fail("frame.ready fell")
      if (offering && dut.io.boxes.ready.peek().litToBoolean) next += 1
      if (r && dut.io.pairs.valid.peek().litToBoolean) {
        val ps = dut.io.pairs.bits.pairs.filter(_.valid.peek().litToBoolean)
          .map(x => (x.bits.i.peek().litValue.toInt, x.bits.j.peek().litValue.toInt))
        beats += BinningCycleModel.BeatAt(t, ps.toSeq)
      }
      dut.io.debug.foreach { probes =>
        for (gr <- 0 until p.groups) {
          val pr = probes(gr)
          if (pr.write.valid.peek().litToBoolean)
            writes += BinningCycleModel.WriteAt(t, gr, pr.write.bits.address.peek().litValue.toInt, pr.write.bits.index.peek().litValue.toInt)
          if (pr.issue.peek().litToBoolean)
            issues(gr) += ((t, pr.lanes.map(l =>
              if (l.valid.peek().litToBoolean) Some((l.i.peek().litValue.toInt, l.j.peek().litValue.toInt, l.hit.peek().litToBoolean))
              else None).toVector))
        }
      }
      if (dut.io.summary.valid.peek().litToBoolean) {
        val s = dut.io.summary.bits
        summary = Some(FrameOutcome(
          beats.result(), t, s.error.peek().litValue.toInt, s.detail.peek().litValue.toLong, s.records.peek().litValue.toLong,
          s.boxes.peek().litValue.toLong, s.entries.peek().litValue.toLong, s.maxGroupEntries.peek().litValue.toLong,
          s.cycles.peek().litValue.toLong, s.intakeCycles.peek().litValue.toLong, s.issueCycles.peek().litValue.toLong,
          s.stallCycles.peek().litValue.toLong, writes.result(), issues.map(_.result()).toVector))
      }
      dut.clock.step()
      t += 1
    }
    dut.io.boxes.valid.poke(false.B)
    dut.io.pairs.ready.poke(false.B)
    dut.io.summary.ready.poke(false.B)
    dut.io.summary.valid.expect(false.B)
    dut.io.pairs.valid.expect(false.B)
    summary
  }
}

/** How the binning specs simulate the core: Verilator, one compiled model per suite and configuration. */
trait BinningSimulators extends ChiselScalatestTester { this: TestSuite =>
  def onVerilator(p: BinningParams)(body: (BinningCore, BinningDriver) => Unit): Unit = {
    val dir = s"test_run_dir/verilator/${getClass.getSimpleName}/${p.fingerprint.replaceAll("[=,/]", "_")}" +
      (if (p.faults.nonEmpty) p.faults.mkString("_", "_", "") else "")
    test(new BinningCore(p)).withAnnotations(Seq(VerilatorBackendAnnotation, CachingAnnotation, TargetDirAnnotation(dir))) { dut =>
      val d = new BinningDriver(dut)
      d.idleInputs()
      body(dut, d)
    }
  }
}
