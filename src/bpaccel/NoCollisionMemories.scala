package bpaccel

import java.nio.file.Path

/** Tells synthesis that no memory is read and written at the same row in the
  * same cycle, so it need not build the collision behaviour.
  *
  * firtool emits each `SyncReadMem` as a registered read address and a read
  * of the array, which synthesis reads as a write-first (transparent) read,
  * and a block RAM's read and write ports give no such guarantee against
  * each other: a tool then adds a bypass after the block RAM (the last
  * write's data and row, a row compare and a multiplexer on every read bit;
  * at seed m = 8 about 45 LUT4 and 50 flip-flops per memory, 48 memories, in
  * front of the rotator). Both engines assert that a read whose data they
  * use never meets a write (`readsNeverMeetWrites` in [[SeedEngine]],
  * [[StreamReader]]), so each memory array gets the attribute every major
  * tool reads as "no read-during-write check":
  *
  *  - `ramstyle = "no_rw_check"`: Intel Quartus, and Yosys;
  *  - `syn_ramstyle = "no_rw_check"`: Synopsys Synplify (Lattice Diamond and
  *    Radiant, Microchip Libero), and Yosys;
  *  - `rw_addr_collision = "no"`: AMD Vivado (its default for this shape
  *    adds no bypass either).
  *
  * Each keeps the tool's own choice of RAM kind.
  */
object NoCollisionMemories {
  val attribute = """(* ramstyle = "no_rw_check", syn_ramstyle = "no_rw_check", rw_addr_collision = "no" *)"""

  /** Marks the array of every memory module `mem_*.sv` that `dir/filelist.f` lists; returns their files. */
  def rewrite(dir: Path): Seq[String] = {
    val memories = SingleClockMemories.memoryFiles(dir)
    memories.foreach(MemoryAttributes.mark(_, attribute, "NoCollisionMemories"))
    memories.map(_.getFileName.toString)
  }
}
