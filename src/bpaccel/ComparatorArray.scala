package bpaccel

import chisel3._

/** 3m greater-or-equal and 3m less-or-equal comparators feeding m six-input
  * AND gates: lane k reports whether a(k) and b(k) overlap. Overlap is
  * inclusive on every axis (touching boxes overlap), as in Bullet's test.
  */
class ComparatorArray(p: AccelParams) extends Module {
  val io = IO(new Bundle {
    val a    = Input(Vec(p.m, new Aabb(p.keyWidth)))
    val b    = Input(Vec(p.m, new Aabb(p.keyWidth)))
    val hits = Output(UInt(p.m.W))
  })
  io.hits := VecInit(io.a.zip(io.b).map { case (a, b) =>
    (0 until 3).map(axis => a.min(axis) <= b.max(axis) && a.max(axis) >= b.min(axis)).reduce(_ && _)
  }).asUInt
}
