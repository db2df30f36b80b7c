package bpaccel.shell

import bpaccel.AccelError

/** The stream protocol's constants (docs/protocol.md): opcodes, the
  * command header, the reply trailer and every error code. The RTL, the C
  * header and the documentation take them from here.
  */
object Protocol {
  val Version: Int = 1
  val TrailerMagic: Int = 0xb7

  case class Opcode(name: String, code: Int, doc: String)
  val Frame = Opcode("FRAME", 0x01, "a whole frame for the binning device: n, grid, then n boxes")
  val Cells = Opcode("CELLS", 0x02, "a batch of cells for the host-partitioned devices (seed, stream)")
  val opcodes: Seq[Opcode] = Seq(Frame, Cells)

  /** Words of the trailer that ends every reply. */
  val TrailerWords: Int = 16

  /** The trailer's fields: (name, first word, words, meaning); 64-bit fields are lo, hi. */
  case class TrailerField(name: String, word: Int, words: Int, doc: String)
  val trailerFields: Seq[TrailerField] = Seq(
    TrailerField("HEADER", 0, 1, "[31:24] magic 0xB7, [23:16] opcode, [15:8] error code, [7:0] flags (0)"),
    TrailerField("DETAIL", 1, 1, "error detail: the cell or box the error names, else 0"),
    TrailerField("RECORDS", 2, 1, "records sent before this trailer"),
    TrailerField("BOXES", 3, 1, "boxes received"),
    TrailerField("DEVICE_CYCLES", 4, 2, "core cycles of the command: intake plus runs"),
    TrailerField("STALL_CYCLES", 6, 2, "core cycles lost waiting for room on the output"),
    TrailerField("ISSUE_CYCLES", 8, 2, "core cycles the comparators were given work"),
    TrailerField("PAIRS", 10, 2, "overlapping pairs found"),
    TrailerField("INTAKE_CYCLES", 12, 2, "core cycles outside the runs: loading that no run hides, and the starts"),
    TrailerField("CELLS", 14, 1, "cells run (CELLS); 0 for other commands"),
    TrailerField("RESERVED", 15, 1, "0")
  )
  def trailerWord(name: String): Int = trailerFields.find(_.name == name).get.word

  /** Every error code a trailer or the LAST_REPLY register can carry: the
    * core's own (AccelError, same numbers) and the shell's.
    */
  case class ErrorCode(name: String, code: Int, doc: String)
  private val coreDocs = Map(
    "NONE" -> "the command succeeded",
    "COUNT_OVER_CAPACITY" -> "a cell's count (FRAME: n) is above the capacity (detail: the cell; FRAME: 0)",
    "COUNT_OVER_LOADED" -> "core only: a start with fewer boxes loaded",
    "LOAD_OVERFLOW" -> "core only: a box beyond the capacity",
    "SPLIT_OUT_OF_RANGE" -> "a cell's split is not 0 and not below its count (detail: the cell)",
    "SPLIT_UNSUPPORTED" -> "a split other than 0 on a device without bipartite runs (detail: the cell)"
  )
  val coreErrors: Seq[ErrorCode] =
    AccelError.names.map { case (name, e) => ErrorCode(name, AccelError.code(e), coreDocs(name)) }
  val BadCommand     = ErrorCode("BAD_COMMAND", 16, "unknown opcode, wrong version, or nonzero bits [31:16] in the header: the packet is drained, the reply is the trailer")
  val LengthMismatch = ErrorCode("LENGTH_MISMATCH", 17, "TLAST before the command's last item, or not on the beat that holds it, or nonzero padding (detail: CELLS: the cell being read, or the cell count when data follows the last cell; FRAME: the boxes the packet carried whole up to its TLAST, or n when data follows the n-th box)")
  val KeyTooWide     = ErrorCode("KEY_TOO_WIDE", 18, "a key has bits set above the device's key width (detail: the box, counted over the command from 0)")
  val Aborted        = ErrorCode("ABORTED", 19, "CONTROL.ABORT ended the command; the rest of its packet is drained")
  val KeyOutOfGrid   = ErrorCode("KEY_OUT_OF_GRID", 20, "FRAME: a key's cell is outside the grid (detail: the box)")
  val BoxSpansCells  = ErrorCode("BOX_SPANS_CELLS", 21, "FRAME: a box spans more than two cells on an axis (detail: the box)")
  val GroupOverflow  = ErrorCode("GROUP_OVERFLOW", 22, "FRAME: a lane group's memory is full (detail: the box)")
  val BadGrid        = ErrorCode("BAD_GRID", 23, "FRAME: the shift is above the device's MAX_SHIFT, a dimension is 0 or above 2^CELL_BITS, or a reserved header bit is set (detail: 0)")
  val BoxInverted    = ErrorCode("BOX_INVERTED", 24, "FRAME: a box's min key is above its max key on an axis (detail: the box)")
  val shellErrors: Seq[ErrorCode] =
    Seq(BadCommand, LengthMismatch, KeyTooWide, Aborted, KeyOutOfGrid, BoxSpansCells, GroupOverflow, BadGrid, BoxInverted)
  val errors: Seq[ErrorCode] = coreErrors ++ shellErrors
  require(errors.map(_.code).distinct.length == errors.length, "error codes must be distinct")
  require(errors.forall(_.code < 256), "error codes fit the trailer's 8 bits")

  /** The protocol's code of each of the binning core's error codes (bpaccel.binning.BinningErrorCode), matched by name. */
  val frameErrors: Seq[(Int, ErrorCode)] = bpaccel.binning.BinningErrorCode.names.map { case (name, core) =>
    core -> errors.find(_.name == name).getOrElse(sys.error(s"the protocol has no code for the binning core's $name"))
  }
}
