package bpaccel.binning

import scala.util.Random

/** Design-space table of the binning device on a scene like the benchmark's
  * (8000 boxes, BinScenes.benchLike), from the cycle model: the numbers
  * docs/binning.md quotes and the defaults were picked by. Modelled cycles,
  * not a hardware measurement.
  *
  * ./scripts/sbt "Test/runMain bpaccel.binning.BinningExplore [boxes] [seed]"
  */
object BinningExplore {
  case class Row(p: BinningParams, cells: Int, r: BinningCycleModel.Result) {
    def maxEntries: Int = r.binned.groups.map(_.length).max
    def line: String = {
      val ph = r.phases.get
      val worst = ph.groupDone.indices.maxBy(ph.groupDone)
      val compute = ph.groupDone(worst) - ph.compute(worst)
      val sort = ph.compute(worst) - ph.sort(worst)
      val laneUse = r.binned.groups.indices.map(gr => r.ops(gr).map(_.op.lanes.count(_.isDefined)).sum).sum.toDouble /
        (p.lanes.toDouble * (r.summaryCycle - ph.prefix))
      f"G=${p.groups}%2d g=${p.g} w=${p.intakeBoxes} P=${p.pairsPerBeat}%2d D=$cells%2d | entries ${r.binned.entries}%6d max/group $maxEntries%5d " +
        f"DP16KD ${p.dp16kdEstimate()}%3d | intake ${ph.prefix}%5d prefix ${ph.sort(worst) - ph.prefix}%4d sort $sort%5d compute $compute%5d " +
        f"drain ${r.summaryCycle - ph.groupDone.max}%3d | total ${r.summaryCycle}%6d (${100.0 * r.summaryCycle / 14508}%5.1f %%) " +
        f"issue ${r.issueCycles}%6d pairs ${r.pairs.length}%6d stall-free lanes ${100 * laneUse}%4.1f %%"
    }
  }

  def row(p: BinningParams, boxes: Seq[BinScenes.FloatBox], edge: Double, cells: Int,
          offer: Long => Boolean = _ => true): Row = {
    val f = BinScenes.quantize(p, boxes, edge, cells)
    Row(p, cells, BinningCycleModel.run(p, f, offer = offer))
  }

  def main(args: Array[String]): Unit = {
    val n    = args.headOption.map(_.toInt).getOrElse(8000)
    val seed = args.lift(1).map(_.toInt).getOrElse(1)
    val (boxes, edge) = BinScenes.benchLike(new Random(seed), n)
    println(f"scene: $n boxes, edge $edge%.2f, largest extent ${boxes.map(b => b.hi.zip(b.lo).map { case (h, l) => h - l }.max).max}%.3f")
    if (args.lift(2).contains("defaults")) {
      val d = BinningParams()
      println(s"defaults: $d")
      for (cells <- Seq(8, 12, 14, 16)) println("host at w boxes/cycle:    " + row(d, boxes, edge, cells).line)
      // A 256-bit stream carries 8 words a beat: 2.67 boxes of 3 words; the shell hands over 4 in 2 of 3 cycles.
      for (cells <- Seq(12, 16)) println("host at 2.67 boxes/cycle: " + row(d, boxes, edge, cells, t => t % 3 != 0).line)
      for (cells <- Seq(12, 16)) println("P = 4:                    " + row(d.copy(pairsPerBeat = 4), boxes, edge, cells).line)
      return
    }
    if (args.lift(2).contains("queues")) {
      val base = BinningParams(keyWidth = 12, cellBits = 4, boxCapacity = 8192, groupCapacity = 8192)
      for ((lq, mq) <- Seq(1 -> 1, 1 -> 2, 1 -> 4, 2 -> 2, 2 -> 4, 4 -> 8); cells <- Seq(12, 16)) {
        val p = base.copy(laneQueueDepth = lq, maskQueueDepth = mq)
        println(s"lane queue $lq, beat queue $mq: " + row(p, boxes, edge, cells).line)
      }
      return
    }
    val shapes = Seq(Seq(1, 1, 1) -> 8, Seq(2, 1, 1) -> 4, Seq(2, 2, 1) -> 2, Seq(2, 2, 2) -> 1)
    val base = BinningParams(keyWidth = 12, cellBits = 4, boxCapacity = 8192, groupCapacity = 8192)
    for ((gb, g) <- shapes; cells <- Seq(8, 12, 14, 16)) {
      val p = base.copy(groupBits = gb, lanesPerGroup = g, intakeBoxes = 4, pairsPerBeat = 8.min(1 << gb.sum))
      println(row(p, boxes, edge, cells).line)
    }
    println("-- intake width and output width at G = 32, g = 2")
    for (w <- Seq(2, 3, 4, 6, 8); pp <- Seq(4, 8); cells <- Seq(12, 16)) {
      val p = base.copy(groupBits = Seq(2, 2, 1), lanesPerGroup = 2, intakeBoxes = w, pairsPerBeat = pp)
      println(row(p, boxes, edge, cells).line)
    }
  }
}
