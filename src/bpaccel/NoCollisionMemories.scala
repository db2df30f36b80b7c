package bpaccel

import java.nio.file.Path

/** Tells synthesis that no memory is read and written at the same row in the
  * same cycle, so it need not build the collision behaviour.
  *
  * firtool emits each `SyncReadMem` as a registered read address, which
  * Yosys reads as a write-first (transparent) read, and a block RAM's read
  * and write ports give no such guarantee against each other: Yosys then
  * adds a bypass (the last write's data and row, a row compare and a
  * multiplexer on every read bit) after the block RAM. At seed m = 8 that is
  * about 45 LUT4 and 50 flip-flops per memory, 48 memories, and the
  * multiplexer sat between the block RAM and the rotator's input register
  * (the critical path, 110.1 MHz). Both engines assert that a read whose
  * data they use never meets a write (see `readsNeverMeetWrites` in
  * [[SeedEngine]] and [[StreamEngine]]), so `(* no_rw_check *)` on the array
  * is true, and Yosys then maps the memory to the block RAM alone. Vendor
  * tools ignore the attribute, as Debian's Yosys 0.23 (the Xilinx estimate) does.
  */
object NoCollisionMemories {
  val attribute = "(* no_rw_check *)"

  /** Marks the array of every memory module `mem_*.sv` that `dir/filelist.f` lists; returns their files. */
  def rewrite(dir: Path): Seq[String] = {
    val memories = SingleClockMemories.memoryFiles(dir)
    memories.foreach(MemoryAttributes.mark(_, attribute, "NoCollisionMemories"))
    memories.map(_.getFileName.toString)
  }
}
