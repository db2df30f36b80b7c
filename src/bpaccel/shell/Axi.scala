package bpaccel.shell

import chisel3._

/** AXI4-Lite, as the manager drives it (the shell's port is Flipped): 32-bit
  * data, no AxPROT (the shell ignores protection), signal names as in the
  * AMBA specification so that tools and cocotbext-axi find them by prefix.
  */
class AxiLite(addressBits: Int) extends Bundle {
  val awaddr  = Output(UInt(addressBits.W))
  val awvalid = Output(Bool())
  val awready = Input(Bool())
  val wdata   = Output(UInt(32.W))
  val wstrb   = Output(UInt(4.W))
  val wvalid  = Output(Bool())
  val wready  = Input(Bool())
  val bresp   = Input(UInt(2.W))
  val bvalid  = Input(Bool())
  val bready  = Output(Bool())
  val araddr  = Output(UInt(addressBits.W))
  val arvalid = Output(Bool())
  val arready = Input(Bool())
  val rdata   = Input(UInt(32.W))
  val rresp   = Input(UInt(2.W))
  val rvalid  = Input(Bool())
  val rready  = Output(Bool())
}

object AxiLite {
  val Okay: Int   = 0
  val SlvErr: Int = 2
}

/** AXI4-Stream as the transmitter drives it: no TKEEP on the way in (every
  * byte counts, packets are whole beats), no TUSER, no TID/TDEST.
  */
class AxiStream(bits: Int) extends Bundle {
  val tdata  = Output(UInt(bits.W))
  val tvalid = Output(Bool())
  val tready = Input(Bool())
  val tlast  = Output(Bool())
}

/** The output stream: TKEEP too (always all ones), which DMA engines such as XDMA's C2H expect. */
class AxiStreamWithKeep(bits: Int) extends AxiStream(bits) {
  val tkeep = Output(UInt((bits / 8).W))
}

/** One beat of the input stream inside the shell: data and TLAST. */
class InputBeat(bits: Int) extends Bundle {
  val data = UInt(bits.W)
  val last = Bool()
}

/** One beat of a reply inside the shell: also whether it belongs to the trailer (for the register bank). */
class OutputBeat(bits: Int) extends InputBeat(bits) {
  val trailer = Bool()
}
