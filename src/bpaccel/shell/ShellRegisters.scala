package bpaccel.shell

import java.util.zip.CRC32

import bpaccel.Arch

/** The shell's register map (docs/registers.md is generated from it). */
object ShellRegisters {
  import Access._

  /** "BPAC" in ASCII, first letter in the lowest byte. */
  val Id: BigInt = BigInt("43415042", 16)
  /** Bumped whenever a register or field changes meaning. */
  val MapVersion: Int = 1

  val ControlOffset = 0x100
  val CountersOffset = 0x120

  /** The 64-bit counters, in address order from CountersOffset; all count since reset or soft reset. */
  val counterNames: Seq[(String, String)] = Seq(
    "REPLIES" -> "replies delivered on the output stream (trailers sent)",
    "ERRORS" -> "replies whose trailer carried an error",
    "RECORDS" -> "records delivered, summed over replies",
    "BOXES" -> "boxes received, summed over replies",
    "DEVICE_CYCLES" -> "core cycles of the commands (trailers' DEVICE_CYCLES summed)",
    "INTAKE_CYCLES" -> "core cycles outside runs (trailers' INTAKE_CYCLES summed)",
    "ISSUE_CYCLES" -> "core cycles the comparators had work (trailers' ISSUE_CYCLES summed)",
    "STALL_CYCLES" -> "core cycles lost to the output (trailers' STALL_CYCLES summed)",
    "PAIRS" -> "overlapping pairs found (trailers' PAIRS summed)",
    "BUSY_CYCLES" -> "bus clock cycles with STATUS.BUSY set"
  )

  /** The CRC-32 of the configuration string, so a driver can tell its header was made for this bitstream. */
  def fingerprint(p: ShellParams): Long = { val c = new CRC32; c.update(p.fingerprint.getBytes("US-ASCII")); c.getValue }

  /** The interrupt causes, one bit each, as IRQ_ENABLE and IRQ_STATUS hold them. */
  private def interruptCauses(access: Access): Seq[Field] = Seq(
    Field("REPLY", 0, 1, access, "a reply's trailer left the output stream"),
    Field("ERROR", 1, 1, access, "a reply with an error left the output stream")
  )

  private def capability(name: String, offset: Int, value: BigInt, doc: String, width: Int = 32): Register =
    Register(name, offset, doc, Seq(Field("VALUE", 0, width, ReadOnly, doc, constant = Some(value))))

  /** What the capability registers say of a core. */
  private case class CoreFacts(
    lanes: Int, capacity: Int, batchCells: Int, bipartite: Boolean, overlapsLoads: Boolean, runOverhead: Int,
    readLatency: Int, laneGroups: Int, lanesPerGroup: Int, cellBits: Int, intakeBoxes: Int
  )
  private def facts(core: ShellCoreParams): CoreFacts = core match {
    case ShellCoreParams.Cells(c) =>
      CoreFacts(c.m, c.capacity, c.batchCells, c.bipartiteRuns, c.overlapsLoads, c.runOverheadCycles,
        if (c.arch == Arch.Stream) c.readLatency else 0, laneGroups = 1, lanesPerGroup = c.m, cellBits = 0, intakeBoxes = 1)
    case ShellCoreParams.Binning(b) =>
      CoreFacts(b.lanes, b.boxCapacity, batchCells = 0, bipartite = false, overlapsLoads = false, runOverhead = 0,
        readLatency = 0, laneGroups = b.groups, lanesPerGroup = b.g, cellBits = b.cellBits, intakeBoxes = b.intakeBoxes)
  }

  def apply(p: ShellParams): RegisterMap = {
    val c = facts(p.core)
    def flag(b: Boolean): BigInt = if (b) 1 else 0
    val identity = Seq(
      capability("ID", 0x000, Id, "\"BPAC\": a bpaccel shell answers here"),
      Register("VERSION", 0x004, "versions of what the shell speaks", Seq(
        Field("PROTOCOL", 0, 8, ReadOnly, "stream protocol version (docs/protocol.md)", constant = Some(Protocol.Version)),
        Field("REGISTER_MAP", 8, 8, ReadOnly, "register map version", constant = Some(MapVersion))
      )),
      capability("FINGERPRINT", 0x008, fingerprint(p), "CRC-32 of the configuration string (BPACCEL_SHELL_FINGERPRINT_TEXT)")
    )
    val capabilities = Seq(
      capability("ARCH", 0x010, p.core.archId, s"architecture: ${Arch.all.map(a => s"${a.id} ${a.name}").mkString(", ")}, 2 binning"),
      capability("OPCODES", 0x014, p.opcodes.map(o => BigInt(1) << o.code).sum, "bit n set: the device answers opcode n"),
      capability("LANES", 0x018, c.lanes, "m: pair tests per cycle"),
      capability("CAPACITY", 0x01c, c.capacity, "most boxes in one cell (CELLS) or frame (FRAME)"),
      capability("KEY_WIDTH", 0x020, p.core.keyWidth, "bits of a key; higher bits of a key's slot must be 0"),
      capability("INDEX_WIDTH", 0x024, p.core.indexWidth, "bits of a box index in a record"),
      capability("STREAM_BITS", 0x028, p.streamBits, "TDATA bits of both streams"),
      capability("BATCH_CELLS", 0x02c, c.batchCells, "cell counts the core queues ahead (CELLS)"),
      Register("FEATURES", 0x030, "what the device can do", Seq(
        Field("BIPARTITE", 0, 1, ReadOnly, "cells may carry a split (bipartite runs)", constant = Some(flag(c.bipartite))),
        Field("OVERLAPS_LOADS", 1, 1, ReadOnly, "a cell loads while the one before runs", constant = Some(flag(c.overlapsLoads))),
        Field("DUAL_CLOCK", 2, 1, ReadOnly, "the core runs on core_clk", constant = Some(flag(p.dualClock)))
      )),
      capability("RUN_OVERHEAD_CYCLES", 0x034, c.runOverhead, "cycles of a run beyond issues and stalls, after its startup"),
      capability("READ_LATENCY", 0x038, c.readLatency, "a run's startup cycles (stream; 0 for the seed and binning)"),
      Register("FORMAT", 0x03c, "words of the stream's items", Seq(
        Field("BOX_WORDS", 0, 8, ReadOnly, "words of one box: 3 (keys of 16 bits or fewer) or 6", constant = Some(p.boxWords)),
        Field("RECORD_WORDS", 8, 8, ReadOnly, "words of one record: CELLS indices, cell and mask; FRAME a pair's indices", constant = Some(p.recordWords)),
        Field("TRAILER_WORDS", 16, 8, ReadOnly, "words of the trailer", constant = Some(Protocol.TrailerWords)),
        Field("INDEX_WORDS", 24, 8, ReadOnly, "words of a record's indices: 1 ({j, i}) or 2 (i, j)", constant = Some(p.indexWords))
      )),
      capability("LANE_GROUPS", 0x040, c.laneGroups, "lane groups (binning; 1 for the CELLS devices)"),
      capability("LANES_PER_GROUP", 0x044, c.lanesPerGroup, "lanes of each group"),
      capability("CELL_BITS", 0x048, c.cellBits, "binning: cells per axis at most 2^CELL_BITS (0: no binning)"),
      capability("INTAKE_BOXES", 0x04c, c.intakeBoxes, "boxes the core takes a cycle at most")
    )
    val control = Seq(
      Register("CONTROL", ControlOffset, "actions; each bit starts its action once and reads 0", Seq(
        Field("ABORT", 0, 1, WriteOnePulse, "end the current command at once: its reply is the records so far and a trailer with ABORTED; the rest of its packet is drained"),
        Field("SOFT_RESET", 1, 1, WriteOnePulse, "reset the datapath of both clock domains, the FIFOs, STATUS, LAST_REPLY, LAST_DETAIL and the counters; IRQ_ENABLE and IRQ_STATUS keep their bits; the streams drop what they hold (halt and flush the DMA first, then wait for STATUS.READY)")
      )),
      Register("STATUS", ControlOffset + 0x4, "state of the streams and the core", Seq(
        Field("READY", 0, 1, ReadOnly, "both clock domains are out of reset: the input stream may send"),
        Field("BUSY", 1, 1, ReadOnly, "a command was received whose reply has not yet left"),
        Field("IN_PACKET", 2, 1, ReadOnly, "the input stream is inside a packet (a beat taken, not yet TLAST)"),
        Field("REPLY_OPEN", 3, 1, ReadOnly, "the output stream is inside a reply (a beat sent, not yet TLAST)"),
        Field("ABORTING", 4, 1, ReadOnly, "an abort is crossing to the core clock"),
        Field("RESETTING", 5, 1, ReadOnly, "a soft reset is under way")
      )),
      Register("LAST_REPLY", ControlOffset + 0x8, "word 0 of the last trailer delivered", Seq(
        Field("FLAGS", 0, 8, ReadOnly, "its flags (0)"),
        Field("ERROR", 8, 8, ReadOnly, "its error code (docs/protocol.md)"),
        Field("OPCODE", 16, 8, ReadOnly, "its command's opcode"),
        Field("MAGIC", 24, 8, ReadOnly, "0xB7 once a reply was delivered")
      )),
      Register("LAST_DETAIL", ControlOffset + 0xc, "the error detail of the last reply delivered", Seq(
        Field("VALUE", 0, 32, ReadOnly, "the cell or box its error names")
      )),
      Register("IRQ_ENABLE", ControlOffset + 0x10, "which IRQ_STATUS bits raise the interrupt line", interruptCauses(ReadWrite)),
      Register("IRQ_STATUS", ControlOffset + 0x14, "interrupt causes; write ones to clear", interruptCauses(WriteOneToClear))
    )
    val counters = counterNames.zipWithIndex.flatMap { case ((name, doc), i) =>
      RegisterMap.counter64(name, CountersOffset + 8 * i, doc)
    }
    RegisterMap("bpaccel_shell", "AXI4-Lite registers of the bpaccel AXI shell", identity ++ capabilities ++ control ++ counters, addressBits = 12)
  }
}
