package bpaccel.shell

/** How software and hardware see a register field. */
sealed abstract class Access(val name: String, val rdlSw: String, val rdlHw: String)
object Access {
  /** Hardware drives it; writes are ignored. A field with a constant value is a capability. */
  case object ReadOnly extends Access("RO", "r", "w")
  /** Software writes, hardware reads. */
  case object ReadWrite extends Access("RW", "rw", "r")
  /** Hardware sets bits, software clears them by writing ones (W1C). */
  case object WriteOneToClear extends Access("W1C", "rw", "w")
  /** Writing a one starts an action for one cycle; reads return 0. */
  case object WriteOnePulse extends Access("W1P", "w", "r")
}

/** One field of a register: bits [lsb + width - 1 : lsb]. */
case class Field(
  name: String,
  lsb: Int,
  width: Int,
  access: Access,
  doc: String,
  reset: BigInt = 0,
  constant: Option[BigInt] = None
) {
  require(width >= 1 && lsb >= 0 && lsb + width <= 32, s"field $name: bits [${lsb + width - 1}:$lsb] outside 32 bits")
  require(constant.forall(c => access == Access.ReadOnly && c >= 0 && c.bitLength <= width),
    s"field $name: a constant must be read-only and fit $width bits")
  def msb: Int = lsb + width - 1
  def mask: BigInt = ((BigInt(1) << width) - 1) << lsb
  /** The value software reads after reset. */
  def resetValue: BigInt = constant.getOrElse(reset)
}

/** One 32-bit register at a byte offset.
  *
  * @param counter  the 64-bit counter this register is half of: reading the
  *                 low half copies the high half into a shadow that the high
  *                 register returns, so lo then hi read one value
  * @param highHalf this is the counter's high half (its shadow)
  */
case class Register(
  name: String,
  offset: Int,
  doc: String,
  fields: Seq[Field],
  counter: Option[String] = None,
  highHalf: Boolean = false
) {
  require(offset % 4 == 0, s"register $name: offset 0x${offset.toHexString} is not word aligned")
  require(fields.nonEmpty, s"register $name has no field")
  for (Seq(a, b) <- fields.sortBy(_.lsb).sliding(2) if fields.length > 1)
    require(a.msb < b.lsb, s"register $name: fields ${a.name} and ${b.name} overlap")
  require(fields.map(_.name).distinct.length == fields.length, s"register $name: field names repeat")
  def resetValue: BigInt = fields.map(f => f.resetValue << f.lsb).sum
}

/** A register map: the one description from which the RTL register bank,
  * the C header, the SystemRDL and docs/registers.md are generated.
  */
case class RegisterMap(name: String, doc: String, registers: Seq[Register], addressBits: Int) {
  require(registers.map(_.offset).distinct.length == registers.length, "register offsets repeat")
  require(registers.map(_.name).distinct.length == registers.length, "register names repeat")
  require(registers.forall(_.offset < (1 << addressBits)), s"a register lies beyond the $addressBits-bit address space")
  def apply(name: String): Register = registers.find(_.name == name).getOrElse(sys.error(s"no register $name"))
  /** Every 64-bit counter: its name, low and high register. */
  def counters: Seq[(String, Register, Register)] =
    registers.flatMap(r => r.counter.filter(_ => !r.highHalf).map(c => (c, r, registers.find(h => h.highHalf && h.counter.contains(c)).get)))
}

object RegisterMap {
  /** A 64-bit counter as two registers: NAME_LO at `offset`, NAME_HI at `offset + 4`. */
  def counter64(name: String, offset: Int, doc: String): Seq[Register] = Seq(
    Register(s"${name}_LO", offset, s"$doc, bits [31:0]; reading it latches bits [63:32] for ${name}_HI",
      Seq(Field("VALUE", 0, 32, Access.ReadOnly, "counter bits [31:0]")), counter = Some(name)),
    Register(s"${name}_HI", offset + 4, s"$doc, bits [63:32] as latched by the last read of ${name}_LO",
      Seq(Field("VALUE", 0, 32, Access.ReadOnly, "counter bits [63:32]")), counter = Some(name), highHalf = true)
  )
}
