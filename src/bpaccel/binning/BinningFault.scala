package bpaccel.binning

/** Deliberate design faults of the binning device, one bug each, for the
  * mutant tests (test/bpaccel/binning): each check must fail on the fault it
  * is meant to catch, so that its passing is not vacuous. Only
  * [[BinningParams.faults]] turns one on; without faults the design
  * elaborates exactly as it would without this list.
  */
sealed abstract class BinningFault(val description: String)

object BinningFault {
  /** The lanes test min < max instead of min <= max: touching boxes are missed. */
  case object StrictCompare extends BinningFault("the lanes miss touching boxes")
  /** The lanes report every overlap in every cell both boxes cover: a straddling pair is reported twice. */
  case object NoExactlyOnceRule extends BinningFault("the lanes ignore the exactly-once rule")
  /** Lane k compares while k <= left + 1: it meets an entry of the next cell or block. */
  case object LaneMaskOneTooWide extends BinningFault("a lane compares one entry past its cell's last")
  /** The serializer drops its head beat after the first pair: a beat's other pairs are lost. */
  case object SerializerDropsBeat extends BinningFault("the serializer drops a beat after its first pair")

  /** A merge cluster takes a group's pair while its queue is full: the pair is lost. */
  case object ClusterTakesWhenFull extends BinningFault("a merge cluster takes a pair while its queue is full")
  /** The intake's grid check lets a key through whose cell equals the dimension (> instead of >=). */
  case object OutOfGridOffByOne extends BinningFault("the intake lets a key one cell past the grid through")
  /** The intake counts boxes offered, not taken: a host's pause miscounts them. */
  case object ReceivedCountsOffers extends BinningFault("the intake counts boxes offered instead of taken")

  val all: Seq[BinningFault] = Seq(StrictCompare, NoExactlyOnceRule, LaneMaskOneTooWide, SerializerDropsBeat,
    ClusterTakesWhenFull, OutOfGridOffByOne, ReceivedCountsOffers)
}
