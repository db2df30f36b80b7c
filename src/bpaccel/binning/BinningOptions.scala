package bpaccel.binning

import bpaccel.MemoryStyle

/** A binning core's settings as given on a command line (EmitBinning, EmitShell --arch binning), each left at
  * the defaults' value when not given. [[params]] applies them all in one step: a requirement of
  * [[BinningParams]] that spans two settings (groupBits against cellBits, keyWidth against cellBits) then sees
  * both, whichever order they came in; applied one at a time, the first could fail against the other's default.
  */
final case class BinningOptions(
  groupBits: Option[Seq[Int]] = None,
  lanesPerGroup: Option[Int] = None,
  keyWidth: Option[Int] = None,
  cellBits: Option[Int] = None,
  boxCapacity: Option[Int] = None,
  groupCapacity: Option[Int] = None,
  intakeBoxes: Option[Int] = None,
  pairsPerBeat: Option[Int] = None,
  memoryOutputStages: Option[Int] = None,
  memoryStyle: Option[String] = None,
  debugPort: Option[Boolean] = None
) {
  /** The parameters these settings give over `defaults`; throws IllegalArgumentException for invalid ones. */
  def params(defaults: BinningParams = BinningParams()): BinningParams = defaults.copy(
    groupBits = groupBits.getOrElse(defaults.groupBits),
    lanesPerGroup = lanesPerGroup.getOrElse(defaults.lanesPerGroup),
    keyWidth = keyWidth.getOrElse(defaults.keyWidth),
    cellBits = cellBits.getOrElse(defaults.cellBits),
    boxCapacity = boxCapacity.getOrElse(defaults.boxCapacity),
    groupCapacity = groupCapacity.getOrElse(defaults.groupCapacity),
    intakeBoxes = intakeBoxes.getOrElse(defaults.intakeBoxes),
    pairsPerBeat = pairsPerBeat.getOrElse(defaults.pairsPerBeat),
    memoryOutputStages = memoryOutputStages.getOrElse(defaults.memoryOutputStages),
    memoryStyle = memoryStyle.map(MemoryStyle.fromName).getOrElse(defaults.memoryStyle),
    debugPort = debugPort.getOrElse(defaults.debugPort)
  )
}

object BinningOptions {
  /** Reads --group-bits' "ax,ay,az" (or "axbxc"), the groups' bits per axis: text that is not whole numbers
    * fails in the parser, as any option's does, and a count other than three fails when the parameters are built.
    */
  val groupBitsRead: scopt.Read[Seq[Int]] = scopt.Read.reads(_.split("[x,]").map(_.trim.toInt).toSeq)
}
