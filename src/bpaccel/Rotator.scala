package bpaccel

import chisel3._
import chisel3.util._

/** The m reordering multiplexers: out(k) = in((k + amount) mod m).
  *
  * The seed gives every lane its own selector, starting at (k+1) mod m and
  * stepping by one each cycle; those selectors always equal (k + r) mod m for
  * one shared r, so a rotation by r does the same job. It is built as
  * log2(m) stages of rotations by 2^s mod m, which compose to any r < m for
  * any m (powers of two or not) with O(m log m) 2:1 multiplexers instead of
  * m full m:1 multiplexers.
  */
class Rotator[T <: Data](gen: T, m: Int) extends Module {
  require(m >= 2, s"a rotator needs at least two lanes, got m = $m")
  val amountWidth: Int = log2Ceil(m)
  val io = IO(new Bundle {
    val in     = Input(Vec(m, gen))
    val amount = Input(UInt(amountWidth.W))
    val out    = Output(Vec(m, gen))
  })
  io.out := (0 until amountWidth).foldLeft(io.in) { (stage, bit) =>
    val step = (1 << bit) % m
    VecInit(Seq.tabulate(m)(k => Mux(io.amount(bit), stage((k + step) % m), stage(k))))
  }
}

object Rotator {
  /** Rotates `in` by `amount` lanes; for one lane there is nothing to rotate. */
  def apply[T <: Data](in: Vec[T], amount: UInt): Vec[T] =
    if (in.length == 1) in
    else {
      val r = Module(new Rotator(chiselTypeOf(in.head), in.length))
      r.io.in     := in
      r.io.amount := amount
      r.io.out
    }
}
