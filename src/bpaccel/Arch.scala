package bpaccel

import java.nio.file.Path

/** The two architectures the generator builds; both have the same ports,
  * result beats and schedule (which pairs meet in which lane, in which order).
  * Each carries its own policy, so no other code asks which one it is.
  *
  *  - [[Arch.Seed]]: the published design: 6m striped dual-port memories, an
  *    A/B address sequencer and a rotator.
  *  - [[Arch.Stream]]: one memory read per cycle feeds an m-deep shift register
  *    (the B window); A blocks sit in registers, the next one captured from
  *    the window as it passes. No rotator, memory independent of m.
  */
sealed abstract class Arch(val name: String, val id: Int) {
  /** Objects per run when none is asked for. */
  def defaultCapacity(m: Int): Int

  /** Why `capacity` does not suit this architecture at `m`, if it does not. */
  def capacityProblem(m: Int, capacity: Int): Option[String]

  /** Whether a batch loads its next cell while the current one runs (see [[BatchControl]]). */
  def overlapsLoads: Boolean

  /** Whether runs may be bipartite (a split in [[RunRequest]]); without, a split fails with an error. */
  def bipartiteRuns: Boolean

  /** Objects 0 .. headObjects-1 of a run start it from registers. */
  def headObjects(m: Int): Int

  /** How many coordinate memories there are, their rows and the bits of a row. */
  def memoryCount(p: AccelParams): Int
  def memoryRows(p: AccelParams): Int
  def memoryWidth(p: AccelParams): Int

  /** Cycles from an issue to its hit mask at the result queue. */
  def pipelineLatency(p: AccelParams): Int

  /** Cycles between the start and the first issue of a run of n >= 2 objects. */
  def startupLatency(p: AccelParams): Int

  /** The datapath: memories, schedule and comparators. */
  def engine(p: AccelParams): Engine

  /** Checks the emitted Verilog in `dir` for structure this architecture relies on; throws naming what is wrong. */
  def checkEmitted(p: AccelParams, dir: Path): Unit
}

object Arch {
  /** The seed keeps one set of memories (they already cost 6m block RAMs, the
    * budget that caps its m), so a batch loads a cell only after the last
    * one ran, and its schedule has no jump over the objects of A.
    */
  case object Seed extends Arch("seed", 0) {
    /** One block RAM's rows per memory. */
    def defaultCapacity(m: Int): Int = AccelParams.defaultRows * m
    def capacityProblem(m: Int, capacity: Int): Option[String] =
      Option.when(capacity % m != 0)(
        s"capacity must be a multiple of m so the objects stripe evenly: capacity = $capacity, m = $m")
    def overlapsLoads = false
    def bipartiteRuns = false
    /** Block 0's A objects. */
    def headObjects(m: Int): Int = m
    /** Six striped memories per lane, one coordinate each. */
    def memoryCount(p: AccelParams): Int = 6 * p.m
    def memoryRows(p: AccelParams): Int = p.depth
    def memoryWidth(p: AccelParams): Int = p.keyWidth
    /** Memory read, memory output registers, rotator, comparator and AND registers. */
    def pipelineLatency(p: AccelParams): Int = 1 + p.memoryOutputStages + 3
    def startupLatency(p: AccelParams): Int = 0
    def engine(p: AccelParams): Engine = new SeedEngine(p)
    def checkEmitted(p: AccelParams, dir: Path): Unit = ()
  }

  /** The stream's one memory holds two banks of the capacity, one written
    * while a run reads the other, and its reader jumps over the objects of A
    * a block does not test.
    */
  case object Stream extends Arch("stream", 1) {
    /** Any m: the memory does not grow with it. */
    def defaultCapacity(m: Int): Int = 2048
    def capacityProblem(m: Int, capacity: Int): Option[String] = None
    def overlapsLoads = true
    def bipartiteRuns = true
    /** Block 0's A objects and its window. */
    def headObjects(m: Int): Int = m + 1
    /** One memory of six keys a row; a row is the bank bit over the index. */
    def memoryCount(p: AccelParams): Int = 1
    def memoryRows(p: AccelParams): Int = 2 << p.indexWidth
    def memoryWidth(p: AccelParams): Int = 6 * p.keyWidth
    /** The lanes' lag behind the control ([[StreamEngine.LaneLag]]), comparator and AND registers. */
    def pipelineLatency(p: AccelParams): Int = StreamEngine.LaneLag + 2
    /** The first reads travel to the window's entry while the window and block 0's A objects are copied from the head registers. */
    def startupLatency(p: AccelParams): Int = p.readLatency
    def engine(p: AccelParams): Engine = new StreamEngine(p)
    def checkEmitted(p: AccelParams, dir: Path): Unit = LaneEnables.check(p, dir)
  }

  val all: Seq[Arch] = Seq(Seed, Stream)
  def fromName(name: String): Arch =
    all.find(_.name == name).getOrElse(
      throw new IllegalArgumentException(s"arch must be one of ${all.map(_.name).mkString(", ")}, got arch = $name")
    )
}
