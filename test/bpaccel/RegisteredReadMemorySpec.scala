package bpaccel

import java.nio.file.Paths

import chisel3._
import chisel3.experimental.{IntParam, StringParam}
import chisel3.util.{log2Ceil, HasBlackBoxPath}
import chiseltest._
import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import scala.util.Random

/** The FPGA flow's ECP5 memory (scripts/fpga/ecp5/Ecp5RegisteredReadMemory.v,
  * DP16KD with REGMODE OUTREG) against the Chisel [[RegisteredReadMemory]] it
  * replaces, cycle by cycle on Verilator, with a behavioural DP16KD model
  * (test/resources/ecp5/DP16KD.v; the tools ship only a black box).
  */
class RegisteredReadMemorySpec extends AnyFlatSpec with Simulators with Matchers {

  private def file(path: String): String = Paths.get(path).toAbsolutePath.toString

  class Ecp5Memory(rows: Int, width: Int, regMode: String)
      extends BlackBox(
        Map(
          "ROWS"     -> IntParam(rows),
          "WIDTH"    -> IntParam(width),
          "ROW_BITS" -> IntParam(log2Ceil(rows).max(1)),
          "REGMODE"  -> StringParam(regMode)
        )
      )
      with HasBlackBoxPath {
    override def desiredName = "Ecp5RegisteredReadMemory"
    val io = IO(new Bundle {
      val clock        = Input(Clock())
      val write_enable = Input(Bool())
      val write_row    = Input(UInt(log2Ceil(rows).max(1).W))
      val write_data   = Input(UInt(width.W))
      val read_enable  = Input(Bool())
      val read_row     = Input(UInt(log2Ceil(rows).max(1).W))
      val read_data    = Output(UInt(width.W))
    })
    addPath(file("scripts/fpga/ecp5/Ecp5RegisteredReadMemory.v"))
    addPath(file("test/resources/ecp5/DP16KD.v"))
  }

  /** Both memories on the same inputs. */
  class BothMemories(rows: Int, width: Int, regMode: String) extends Module {
    private val chiselMemory = Module(new RegisteredReadMemory(rows, width))
    val io = IO(chiselMemory.io.cloneType)
    val ecp5Data = IO(Output(UInt(width.W)))
    chiselMemory.io <> io
    private val ecp5 = Module(new Ecp5Memory(rows, width, regMode))
    ecp5.io.clock        := clock
    ecp5.io.write_enable := io.writeEnable
    ecp5.io.write_row    := io.writeRow
    ecp5.io.write_data   := io.writeData
    ecp5.io.read_enable  := io.readEnable
    ecp5.io.read_row     := io.readRow
    ecp5Data := ecp5.io.read_data
  }

  /** Random writes and reads (never of the row being written); returns the cycles whose
    * outputs differed, counted once the first read's data has arrived, and the cycles compared.
    */
  private def mismatches(rows: Int, width: Int, regMode: String, cycles: Int, seed: Int): (Int, Int) = {
    var differ   = 0
    var compared = 0
    onSharedVerilator("BothMemories", (rows, width, regMode))(new BothMemories(rows, width, regMode)) { c =>
      val rng       = new Random(seed)
      val rowBits   = log2Ceil(rows).max(1)
      var readsDone = 0 // enabled reads at least two cycles old
      var recent    = List.empty[Boolean]
      for (cycle <- 0 until cycles) {
        val write    = rng.nextInt(3) != 0
        val writeRow = rng.nextInt(rows)
        // Mostly reads late on, after the memory has filled.
        val read    = rng.nextInt(4) < (if (cycle < cycles / 3) 1 else 3)
        val readRow = Iterator.continually(rng.nextInt(rows)).find(r => !(write && r == writeRow) || rows == 1).get
        c.io.writeEnable.poke(write.B)
        c.io.writeRow.poke(writeRow.U(rowBits.W))
        c.io.writeData.poke(BigInt(width, rng).U(width.W))
        c.io.readEnable.poke((read && !(write && rows == 1)).B)
        c.io.readRow.poke(readRow.U(rowBits.W))
        if (readsDone > 0) {
          compared += 1
          if (c.io.readData.peek().litValue != c.ecp5Data.peek().litValue) differ += 1
        }
        recent = (read && !(write && rows == 1)) :: recent
        if (recent.length > 2) { if (recent.last) readsDone += 1; recent = recent.init }
        c.clock.step()
      }
    }
    (differ, compared)
  }

  // The stream's memory (2048 x 9 tiles), the seed's (256 rows, 18-bit tiles), and a narrow odd one.
  for ((rows, width) <- Seq((2048, 192), (256, 32), (37, 7))) {
    it should s"read every cycle what the Chisel memory reads: $rows x $width, REGMODE OUTREG" in {
      val (differ, compared) = mismatches(rows, width, "OUTREG", cycles = 3000, seed = rows + width)
      compared should be > 1500
      differ shouldBe 0
    }
  }

  it should "give neither the old nor the new word for a row read in the cycle it is written (undefined on the DP16KD)" in {
    test(new RegisteredReadMemory(8, 8)) { c =>
      val (older, newer) = (0x0f, 0x3c)
      def write(row: Int, data: Int): Unit = {
        c.io.writeEnable.poke(true.B); c.io.writeRow.poke(row.U); c.io.writeData.poke(data.U)
      }
      c.io.readEnable.poke(false.B)
      write(3, older)
      c.clock.step()
      write(3, newer)
      c.io.readEnable.poke(true.B)
      c.io.readRow.poke(3.U)
      c.clock.step()
      c.io.writeEnable.poke(false.B)
      c.io.readEnable.poke(false.B)
      c.clock.step()
      c.io.readData.peek().litValue.toInt should (not equal older and not equal newer)
      // Read again without a write: the word that was written.
      c.io.readEnable.poke(true.B)
      c.clock.step()
      c.io.readEnable.poke(false.B)
      c.clock.step()
      c.io.readData.expect(newer.U)
    }
  }

  it should "differ when the block RAM's output register is off (REGMODE NOREG, one cycle early)" in {
    val (differ, compared) = mismatches(256, 32, "NOREG", cycles = 3000, seed = 7)
    compared should be > 1500
    differ should be > compared / 10
  }
}
