package bpaccel.binning

import java.nio.file.{Files, Paths}

import scala.util.Random

import bpaccel.Box

/** Writes the test vectors the host's C++ model of the binning device is
  * checked against (host/tests/device/binning/binning_cycle_vectors.json):
  * frames at the default parameters, each with what BinningCycleModel says
  * of it (error, detail, cycles, issue cycles, the phases of every group,
  * the pairs as a count and an order-free checksum), consumer always ready,
  * the host offering a beat every cycle.
  *
  * ./scripts/sbt "Test/runMain bpaccel.binning.BinningVectors host/tests/device/binning/binning_cycle_vectors.json"
  */
object BinningVectors {
  /** splitmix64 of one pair, summed over the pairs (mod 2^64): the host computes the same. */
  def pairHash(i: Int, j: Int): Long = {
    var z = (i.toLong << 32) + j.toLong + 0x9e3779b97f4a7c15L
    z = (z ^ (z >>> 30)) * 0xbf58476d1ce4e5b9L
    z = (z ^ (z >>> 27)) * 0x94d049bb133111ebL
    z ^ (z >>> 31)
  }

  private def frames(p: BinningParams): Seq[(String, BinFrame)] = {
    val rng = new Random(4141)
    val random = for (round <- 0 until 6; (name, boxes) <- {
      val (shift, dims) = BinScenes.grid(rng, p)
      val n = Seq(0, 1, 7, 60, 300, 500)(round)
      BinScenes.all(rng, n, shift, dims).map { case (nm, b) => (s"$nm n=$n s=$shift d=${dims.mkString("x")}", BinFrame(b, shift, dims)) }
    }) yield (name, boxes)
    val (bench, edge) = BinScenes.benchLike(new Random(1), 8000)
    val benchFrames = Seq(12, 16).map(d => s"bench-like 8000 D=$d" -> BinScenes.quantize(p, bench, edge, d))
    val dense = BinFrame(BinScenes.oneCell(rng, 120, p.maxShift, Seq(4, 4, 2)), p.maxShift, Seq(4, 4, 2))
    val ok = BinScenes.uniform(rng, 40, 6, Seq(5, 5, 5))
    def box(lo: Seq[Long], hi: Seq[Long]) = Box(lo.map(BigInt(_)), hi.map(BigInt(_)))
    val errors = Seq(
      "error COUNT_OVER_CAPACITY" -> BinFrame(ok, 6, Seq(5, 5, 5), header = Some(p.boxCapacity + 1)),
      "error BAD_GRID" -> BinFrame(ok, p.maxShift + 1, Seq(5, 5, 5)),
      "error KEY_OUT_OF_GRID" -> BinFrame(ok.updated(17, box(Seq(0, 0, 0), Seq(10, 5 * 64, 10))), 6, Seq(5, 5, 5)),
      "error BOX_SPANS_CELLS" -> BinFrame(ok.updated(23, box(Seq(0, 0, 0), Seq(10, 10, 130))), 6, Seq(5, 5, 5)),
      "error BOX_INVERTED" -> BinFrame(ok.updated(3, box(Seq(9, 0, 0), Seq(8, 10, 10))), 6, Seq(5, 5, 5)),
      "error LENGTH_MISMATCH" -> BinFrame(ok, 6, Seq(5, 5, 5), header = Some(45)),
      "error GROUP_OVERFLOW" -> BinFrame(Seq.fill(p.groupCapacity + 5)(box(Seq(1, 1, 1), Seq(2, 2, 2))), 6, Seq(5, 5, 5))
    )
    random ++ benchFrames ++ Seq("dense one cell n=120" -> dense) ++ errors
  }

  private def sceneJson(p: BinningParams, name: String, f: BinFrame): String = {
    val r = BinningCycleModel.run(p, f)
    val keys = f.boxes.flatMap(b => b.min ++ b.max).mkString(",")
    val hash = r.pairs.map { case (i, j) => pairHash(i, j) }.sum
    def longs(xs: Seq[Long]) = xs.mkString("[", ",", "]")
    val phases = r.phases.map(ph =>
      s""", "intake_done": ${ph.intakeDone}, "sort_start": ${longs(ph.sort)}, "compute_start": ${longs(ph.compute)}, """ +
        s""""group_done": ${longs(ph.groupDone)}""").getOrElse("")
    s"""{"name": "$name", "shift": ${f.shift}, "dims": [${f.dims.mkString(",")}], "n": ${f.n}, "keys": [$keys], """ +
      s""""error": ${r.error}, "detail": ${r.detail}, "cycles": ${r.cycles}, "issue_cycles": ${r.issueCycles}, """ +
      s""""entries": ${r.binned.entries}, "pairs": ${r.pairs.length}, "pair_hash": "${java.lang.Long.toUnsignedString(hash)}"$phases}"""
  }

  val committed: String = "host/tests/device/binning/binning_cycle_vectors.json"

  /** The file's text for the default parameters. */
  def render(): String = {
    val p = BinningParams()
    val scenes = frames(p).map { case (name, f) => sceneJson(p, name, f) }
    s"""{"generator": "bpaccel.binning.BinningVectors", "fingerprint": "${p.fingerprint}",\n"scenes": [\n""" +
      scenes.mkString(",\n") + "\n]}\n"
  }

  def main(args: Array[String]): Unit = {
    val out = Paths.get(args.headOption.getOrElse(committed))
    Files.createDirectories(out.getParent)
    Files.writeString(out, render())
    println(s"wrote the vectors to $out")
  }
}
