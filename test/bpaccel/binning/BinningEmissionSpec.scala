package bpaccel.binning

import java.nio.file.{Files, Path}

import scala.jdk.CollectionConverters._
import scala.sys.process._

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

import bpaccel.{DistributedMemories, EmitVerilog, NoCollisionMemories, RegisterMemories, SingleClockMemories}

/** What FPGA flows and hosts get from EmitBinning: lint-clean SystemVerilog,
  * memories that synthesis maps to block RAM, LUT RAM or flip-flops as
  * meant, and a C header and JSON file that say the same as the parameters.
  */
class BinningEmissionSpec extends AnyFlatSpec with Matchers {
  private lazy val default = emitted(BinningParams())

  private def emitted(p: BinningParams): (BinningParams, Path) = {
    val dir = Files.createTempDirectory("bpaccel-binning-")
    EmitBinning.emit(p, dir)
    (p, dir)
  }
  private def read(dir: Path, file: String): String = Files.readString(dir.resolve(file))
  private def run(dir: Path, cmd: Seq[String]): (Int, String) = {
    val log = new StringBuilder
    val exit = Process(cmd, dir.toFile).!(ProcessLogger(l => log.append(l).append('\n'), l => log.append(l).append('\n')))
    (exit, log.toString)
  }
  /** The cells Yosys 0.23's synth_ecp5 makes of `module` in `file`. */
  private def ecp5Cells(dir: Path, module: String, file: String): Map[String, Int] = {
    val (exit, log) = run(dir, Seq("yosys", "-q", "-p", s"read_verilog -sv $file; synth_ecp5 -top $module; tee -o $file.stat stat"))
    withClue(log.takeRight(3000)) { exit shouldBe 0 }
    "(?m)^\\s+(\\w+)\\s+(\\d+)$".r.findAllMatchIn(read(dir, s"$file.stat")).map(x => x.group(1) -> x.group(2).toInt).toMap
  }

  behavior of "EmitBinning"

  it should "apply its options in one step, so that their order does not decide whether they are valid" in {
    // groupBits 5 needs cellBits >= 5: set one at a time, the first order checks 5,1,1 against the default 4.
    val forward = EmitBinning.parse(Seq("--group-bits", "5,1,1", "--cell-bits", "5", "--key-width", "14"))
    val backward = EmitBinning.parse(Seq("--key-width", "14", "--cell-bits", "5", "--group-bits", "5,1,1"))
    val p = forward.get.b.params()
    p shouldBe backward.get.b.params()
    (p.groupBits, p.cellBits, p.keyWidth, p.boxCapacity) shouldBe ((Seq(5, 1, 1), 5, 14, BinningParams().boxCapacity))
    // A combination that is invalid in any order is refused by name, when the parameters are built.
    val refused = the[IllegalArgumentException] thrownBy
      EmitBinning.parse(Seq("--cell-bits", "2", "--group-bits", "3,1,1")).get.b.params()
    refused.getMessage should include("groupBits")
    // A group-bits text that is not numbers is a usage error of the parser, not an exception.
    EmitBinning.parse(Seq("--group-bits", "2,two,1")) shouldBe None
  }

  it should "emit SystemVerilog that verilator --lint-only -Wall passes without a warning (the defaults)" in {
    val (_, dir) = default
    val (exit, log) = run(dir, Seq("verilator", "--lint-only", "-Wall", EmitVerilog.lintWaivers, "-F", "filelist.f",
      "--top-module", "BinningCore"))
    withClue(log.take(4000)) { exit shouldBe 0; log.trim shouldBe empty }
  }

  it should "give each group an entry memory, an order memory and a cell table, one clock each and no collision bypass" in {
    val (p, dir) = default
    val memories = SingleClockMemories.memoryFiles(dir).map(_.getFileName.toString).sorted
    memories shouldBe Seq(s"mem_${p.groupCapacity}x${p.entryAddrWidth}.sv", s"mem_${p.groupCapacity}x${p.entryBits}.sv",
      s"mem_${p.localCells}x${p.entryCountWidth}.sv").sorted
    for (m <- memories) withClue(s"$m: ") {
      read(dir, m) should include(NoCollisionMemories.attribute)
      read(dir, m) should not include "R0_clk"
      // Only the cell table asks for LUT RAM.
      (read(dir, m).contains(DistributedMemories.attribute)) shouldBe (m == s"${CellTable.memoryModule(p)}.sv")
    }
    // Each group instantiates the three; there are G groups.
    "(?m)^\\s*LaneGroup\\s+\\w+\\s*\\(".r.findAllIn(read(dir, "BinningCore.sv")).length shouldBe p.groups
  }

  it should "ask for flip-flops for the two-entry queue memories (the lane queues among them) and for no deeper one" in {
    val (p, dir) = default
    val queueMemories = SingleClockMemories.listedFiles(dir).map(_.getFileName.toString).filter(_.startsWith("ram_"))
    val twoEntry = queueMemories.filter(_.startsWith("ram_2x"))
    twoEntry should contain(s"ram_${p.laneQueueDepth}x${p.entryBits}.sv")
    (queueMemories.toSet -- twoEntry) should not be empty // deeper queues exist and stay LUT RAM
    for (m <- queueMemories) withClue(s"$m: ") {
      read(dir, m).contains(RegisterMemories.attribute) shouldBe twoEntry.contains(m)
    }
  }

  it should "map the entry and order memories alone to ECP5 block RAM (DP16KD) and the cell table to LUT RAM" in {
    val (p, dir) = default
    def cells(module: String, file: String): Map[String, Int] = ecp5Cells(dir, module, file)
    def memory(module: String): Map[String, Int] = cells(module, s"$module.sv")
    val entries = memory(s"mem_${p.groupCapacity}x${p.entryBits}")
    entries.getOrElse("DP16KD", 0) shouldBe 4 // 1024 x 71: four 1024 x 18 blocks
    entries.keys.filter(_.startsWith("TRELLIS_DPR")) shouldBe empty
    memory(s"mem_${p.groupCapacity}x${p.entryAddrWidth}").getOrElse("DP16KD", 0) shouldBe 1
    val tableModule = CellTable.memoryModule(p)
    val table = memory(tableModule)
    table.getOrElse("DP16KD", 0) shouldBe 0
    table.getOrElse("TRELLIS_DPR16X4", 0) shouldBe 24 // 128 x 11: 8 x 3 blocks of 16 x 4
    // The attribute does it: without it, Yosys puts the table into a DP16KD of its own.
    Files.writeString(dir.resolve("bare-table.sv"), read(dir, s"$tableModule.sv").replace(s"${DistributedMemories.attribute} ", ""))
    cells(tableModule, "bare-table.sv").getOrElse("DP16KD", 0) shouldBe 1
  }

  it should "map a lane queue's two-entry memory to flip-flops and a deeper queue's to LUT RAM" in {
    val (p, dir) = default
    def cells(module: String, file: String): Map[String, Int] = ecp5Cells(dir, module, file)
    val lane = s"ram_${p.laneQueueDepth}x${p.entryBits}"
    p.laneQueueDepth shouldBe 2
    val registers = cells(lane, s"$lane.sv")
    registers.keys.filter(_.startsWith("TRELLIS_DPR")) shouldBe empty
    registers.getOrElse("TRELLIS_FF", 0) shouldBe 2 * p.entryBits
    registers.getOrElse("LUT4", 0) should be <= p.entryBits + 4 // one 2:1 read mux a bit, a few write enables
    // The attribute does it: without it, Yosys builds the same memory from 18 blocks of 16 x 4 LUT RAM.
    Files.writeString(dir.resolve("bare-lane.sv"), read(dir, s"$lane.sv").replace(s"${RegisterMemories.attribute} ", ""))
    cells(lane, "bare-lane.sv").getOrElse("TRELLIS_DPR16X4", 0) shouldBe (p.entryBits + 3) / 4
    val hitQueue = s"ram_${p.hitQueueDepth}x"
    val deeper = SingleClockMemories.listedFiles(dir).map(_.getFileName.toString.stripSuffix(".sv")).filter(_.startsWith(hitQueue))
    deeper should not be empty
    for (m <- deeper) withClue(s"$m: ") { cells(m, s"$m.sv").getOrElse("TRELLIS_DPR16X4", 0) should be > 0 }
  }

  it should "write a C header and a JSON file with the parameters and every error code" in {
    val (p, dir) = default
    val header = read(dir, EmitBinning.headerFile)
    val json   = read(dir, EmitBinning.jsonFile)
    header should include(s"#define BPACCEL_BIN_GROUPS ${p.groups}\n")
    header should include(s"#define BPACCEL_BIN_LANES ${p.lanes}\n")
    header should include(s"#define BPACCEL_BIN_FINGERPRINT \"${p.fingerprint}\"\n")
    json should include(s"\"lanes_per_group\": ${p.g},")
    json should include(s"\"box_capacity\": ${p.boxCapacity},")
    // What the FPGA flow reads: modules that exist in the emitted files.
    json should include("\"top\": \"BinningCore\",")
    json should include(s"\"memory_module\": \"mem_${p.groupCapacity}x${p.entryBits}\",")
    Files.exists(dir.resolve("BinningCore.sv")) shouldBe true
    Files.exists(dir.resolve(s"mem_${p.groupCapacity}x${p.entryBits}.sv")) shouldBe true
    json should include(s"\"memory_count\": ${2 * p.groups},")
    for ((name, code) <- BinningErrorCode.names) {
      header should include(s"#define BPACCEL_BIN_ERROR_$name $code\n")
      json should include(s"\"error_${name.toLowerCase}\": $code")
    }
    // The JSON parses as flat "key": value lines.
    json.trim.linesIterator.toSeq.drop(1).dropRight(1).foreach(_ should fullyMatch regex "\\s+\"[a-z0-9_]+\": (-?\\d+|\"[^\"]*\"),?")
  }

  it should "refuse parameters that break the design's assumptions, naming them" in {
    the[IllegalArgumentException] thrownBy BinningParams(groupBits = Seq(0, 1, 1)) should have message
      "requirement failed: each of groupBits must lie in 1..cellBits = 4 (two neighbouring cells need different groups), got 0, 1, 1"
    an[IllegalArgumentException] should be thrownBy BinningParams(keyWidth = 4) // no bit left for the offset
    an[IllegalArgumentException] should be thrownBy BinningParams(pairsPerBeat = 33) // more lanes than groups
    an[IllegalArgumentException] should be thrownBy BinningParams(memoryOutputStages = 0,
      memoryStyle = bpaccel.MemoryStyle.Ecp5OutputRegister)
  }
}
