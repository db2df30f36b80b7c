package bpaccel.shell

import scala.collection.immutable.SeqMap

import chisel3._
import chisel3.util._

/** The hardware side of a register map: one port per field that is not a constant.
  *
  *  - read-only field: input `<REG>_<FIELD>`; a 64-bit counter: input `<NAME>` (64 bits)
  *  - read-write field: output `<REG>_<FIELD>`
  *  - write-one-to-clear field: input `<REG>_<FIELD>_set` (bits to set), output `<REG>_<FIELD>` (its value)
  *  - write-one-pulse field: output `<REG>_<FIELD>`, high for the cycle after the write
  */
class RegisterPorts(map: RegisterMap) extends Record {
  val elements: SeqMap[String, Data] = SeqMap.from(map.registers.flatMap { r =>
    if (r.counter.isDefined) (if (r.highHalf) Nil else Seq(r.counter.get -> Input(UInt(64.W))))
    else r.fields.filter(_.constant.isEmpty).flatMap { f =>
      val name = s"${r.name}_${f.name}"
      f.access match {
        case Access.ReadOnly        => Seq(name -> Input(UInt(f.width.W)))
        case Access.ReadWrite       => Seq(name -> Output(UInt(f.width.W)))
        case Access.WriteOneToClear => Seq(s"${name}_set" -> Input(UInt(f.width.W)), name -> Output(UInt(f.width.W)))
        case Access.WriteOnePulse   => Seq(name -> Output(UInt(f.width.W)))
      }
    }
  })
  def apply(name: String): UInt = elements.getOrElse(name, sys.error(s"no register port $name")).asInstanceOf[UInt]
}

/** An AXI4-Lite subordinate holding the registers of `map`.
  *
  * Every output is a register: AWREADY and WREADY are low while an address or
  * data beat is held, BVALID and RVALID and their payloads are flip-flops, so
  * no input reaches an output through logic. A write takes effect when both
  * its address and data are held and no response is waiting; a read returns
  * in the cycle after its address is taken. Unmapped or unaligned addresses
  * answer SLVERR.
  */
class AxiLiteRegisterBank(map: RegisterMap) extends Module {
  val io = IO(new Bundle {
    val axil = Flipped(new AxiLite(map.addressBits))
    val hw   = new RegisterPorts(map)
  })
  private val a = io.axil

  private def index(addr: UInt): UInt = addr(map.addressBits - 1, 2)
  private def at(addr: UInt, r: Register): Bool = index(addr) === (r.offset >> 2).U && addr(1, 0) === 0.U

  // Write channel.
  val awHeld = RegInit(false.B)
  val wHeld  = RegInit(false.B)
  val bValid = RegInit(false.B)
  val bResp  = RegInit(0.U(2.W))
  val awAddr = Reg(UInt(map.addressBits.W))
  val wData  = Reg(UInt(32.W))
  val wStrb  = Reg(UInt(4.W))
  a.awready := !awHeld
  a.wready  := !wHeld
  a.bvalid  := bValid
  a.bresp   := bResp
  when(a.awvalid && !awHeld) { awHeld := true.B; awAddr := a.awaddr }
  when(a.wvalid && !wHeld) { wHeld := true.B; wData := a.wdata; wStrb := a.wstrb }
  when(bValid && a.bready) { bValid := false.B }
  val write     = awHeld && wHeld && !bValid
  val writeMask = FillInterleaved(8, wStrb)
  when(write) {
    awHeld := false.B
    wHeld  := false.B
    bValid := true.B
    bResp  := Mux(map.registers.map(at(awAddr, _)).reduce(_ || _), AxiLite.Okay.U, AxiLite.SlvErr.U)
  }
  private def written(r: Register, f: Field): UInt = Mux(write && at(awAddr, r), (wData & writeMask)(f.msb, f.lsb), 0.U)

  // Field storage and the value each register reads.
  val hiShadow = RegInit(0.U(32.W))
  private val readValue: Seq[(Register, UInt)] = map.registers.map { r =>
    val value: UInt = r.counter match {
      case Some(_) if r.highHalf => hiShadow
      case Some(c)               => io.hw(c)(31, 0)
      case None          => r.fields.map(f => fieldValue(r, f) << f.lsb).reduce(_ | _).pad(32)
    }
    r -> value
  }

  private def fieldValue(r: Register, f: Field): UInt = {
    val name = s"${r.name}_${f.name}"
    (f.access, f.constant) match {
      case (_, Some(c))          => c.U(f.width.W)
      case (Access.ReadOnly, _)  => io.hw(name)
      case (Access.ReadWrite, _) =>
        val reg = RegInit(f.reset.U(f.width.W)).suggestName(name)
        val strobe = Mux(write && at(awAddr, r), writeMask(f.msb, f.lsb), 0.U)
        reg := (reg & ~strobe) | (wData(f.msb, f.lsb) & strobe)
        io.hw(name) := reg
        reg
      case (Access.WriteOneToClear, _) =>
        val reg = RegInit(f.reset.U(f.width.W)).suggestName(name)
        // A set in the cycle of the clear wins: the event is not lost.
        reg := (reg & ~written(r, f)) | io.hw(s"${name}_set")
        io.hw(name) := reg
        reg
      case (Access.WriteOnePulse, _) =>
        io.hw(name) := RegNext(written(r, f), 0.U)
        0.U(f.width.W)
    }
  }

  // Read channel.
  val rValid = RegInit(false.B)
  val rData  = RegInit(0.U(32.W))
  val rResp  = RegInit(0.U(2.W))
  a.arready := !rValid
  a.rvalid  := rValid
  a.rdata   := rData
  a.rresp   := rResp
  when(rValid && a.rready) { rValid := false.B }
  when(a.arvalid && !rValid) {
    rValid := true.B
    val hits = readValue.map { case (r, _) => at(a.araddr, r) }
    rData := Mux1H(hits :+ !hits.reduce(_ || _), readValue.map(_._2) :+ 0.U(32.W))
    rResp := Mux(hits.reduce(_ || _), AxiLite.Okay.U, AxiLite.SlvErr.U)
    for ((c, lo, _) <- map.counters) when(at(a.araddr, lo)) { hiShadow := io.hw(c)(63, 32) }
  }
}
