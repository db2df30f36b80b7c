package bpaccel

import chisel3._

/** 3m greater-or-equal and 3m less-or-equal comparators: lane k's six
  * results say, axis by axis, whether a(k) and b(k) overlap. Overlap is
  * inclusive on every axis (touching boxes overlap), as in Bullet's test.
  * Both architectures register the six results before the AND, so a 32-bit
  * compare's carry chain and the AND are not one stage.
  */
class ComparatorArray(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val a        = Input(Vec(p.m, new Aabb(p.keyWidth)))
    val b        = Input(Vec(p.m, new Aabb(p.keyWidth)))
    val compares = Output(Vec(p.m, UInt(6.W))) // all six set: the lane's boxes overlap
  })
  io.compares := VecInit(io.a.zip(io.b).map { case (a, b) =>
    VecInit((0 until 3).flatMap(axis =>
      if (p.has(Fault.StrictCompare)) Seq(a.min(axis) < b.max(axis), a.max(axis) > b.min(axis))
      else Seq(a.min(axis) <= b.max(axis), a.max(axis) >= b.min(axis))
    )).asUInt
  })
}

object ComparatorArray {
  /** Lane k set when all six of its results are. */
  def hits(compares: Vec[UInt]): UInt = VecInit(compares.map(_.andR)).asUInt
}
