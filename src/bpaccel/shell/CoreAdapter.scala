package bpaccel.shell

import chisel3._
import chisel3.util._

/** What a core reports at the end of a command; the trailer's counters (docs/protocol.md). */
class CommandSummary extends Bundle {
  val records      = UInt(32.W)
  val boxes        = UInt(32.W)
  val cells        = UInt(32.W)
  val runCycles    = UInt(64.W) // DEVICE_CYCLES - INTAKE_CYCLES
  val intakeCycles = UInt(64.W)
  val issueCycles  = UInt(64.W)
  val stallCycles  = UInt(64.W)
  val pairs        = UInt(64.W)
  /** An error the core found in the command's content (0: none), reported with its summary. */
  val error        = new ItemError
}

/** Up to `words` words of reply records, the first `count` of them valid. */
class RecordWords(maxWords: Int) extends Bundle {
  val words = Vec(maxWords, UInt(32.W))
  val count = UInt(log2Ceil(maxWords + 1).W)
}

/** An error an adapter found in an item's content. */
class ItemError extends Bundle {
  val code   = UInt(8.W)
  val detail = UInt(32.W)
}

/** The ports between the shell's command control and a core's adapter.
  *
  * The control reads the command header; for the adapter's opcode it pulses
  * `start`, then offers the body item by item. The adapter says how many
  * words its next item has (`need`), whether it is the command's last
  * (`last`, which may depend on the item's words), whether the item's
  * content is wrong (`itemError`) and whether it can take it now (`ready`).
  * The control takes it (`take`) once the item is whole and not cut short
  * by TLAST, and handles padding, TLAST, draining and aborts itself. On
  * `cancel` (an error or an abort) the adapter stops its core and reports
  * its summary at once; otherwise it reports it after its last record, with
  * the first error its core found in the body, if any (it names content
  * that came before anything the control could find wrong afterwards). A
  * cancel with `ended` (the packet ended before the body's last item) may
  * instead end the core's command on the words that came whole, and report
  * the summary, with the core's error, when the core does.
  */
class AdapterIO(p: ShellParams, recordWords: Int) extends Bundle {
  val start     = Input(Bool())
  val window    = Input(new WordWindow(p))
  val take      = Input(Bool())
  val cancel    = Input(Bool())
  val ended     = Input(Bool())
  val need      = Output(UInt(log2Ceil(p.itemWords + 1).W))
  val last      = Output(Bool())
  val ready     = Output(Bool())
  val itemError = Output(Valid(new ItemError))
  /** Where the body is (the cell being read), for a LENGTH_MISMATCH's detail. */
  val position  = Output(UInt(32.W))
  val records   = Decoupled(new RecordWords(recordWords))
  val summary   = Decoupled(new CommandSummary)
}

/** A core behind the shell: parses its opcode's body, drives the core, formats records. */
abstract class CoreAdapter(val p: ShellParams, val recordWords: Int) extends Module {
  val opcode: Protocol.Opcode
  val io = IO(new AdapterIO(p, recordWords))
}

object CoreAdapter {
  /** The adapter of the configuration's core: the one place that knows which core answers which opcode. */
  def apply(p: ShellParams): CoreAdapter = p.core match {
    case ShellCoreParams.Cells(_)   => new CellsAdapter(p)
    case ShellCoreParams.Binning(_) => new FrameAdapter(p)
  }
}
