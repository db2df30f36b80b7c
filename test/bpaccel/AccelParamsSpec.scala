package bpaccel

import org.scalatest.flatspec.AnyFlatSpec
import org.scalatest.matchers.should.Matchers

class AccelParamsSpec extends AnyFlatSpec with Matchers {
  private def rejection(p: => AccelParams): String =
    intercept[IllegalArgumentException](p).getMessage

  "AccelParams" should "reject m = 0 with a message naming m" in {
    rejection(AccelParams(m = 0, capacity = 8)) should include("m must be at least 1")
  }

  it should "reject a capacity that is not a multiple of m" in {
    rejection(AccelParams(m = 3, capacity = 16, arch = Arch.Seed)) should include("capacity must be a multiple of m")
  }

  it should "reject a capacity below two objects" in {
    rejection(AccelParams(m = 1, capacity = 1)) should include("capacity must be at least 2")
  }

  it should "reject key widths outside 1..64" in {
    rejection(AccelParams(keyWidth = 0)) should include("keyWidth")
    rejection(AccelParams(keyWidth = 65)) should include("keyWidth")
  }

  it should "reject memory output stages outside 0..4" in {
    rejection(AccelParams(memoryOutputStages = -1)) should include("memoryOutputStages")
    rejection(AccelParams(memoryOutputStages = 5)) should include("memoryOutputStages")
  }

  it should "reject the ecp5-outreg memory style without an output register to move, or deeper than one DP16KD column" in {
    val outreg = MemoryStyle.Ecp5OutputRegister
    rejection(AccelParams(memoryOutputStages = 0, memoryStyle = outreg)) should include("memoryOutputStages >= 1")
    rejection(AccelParams(m = 1, capacity = 4096, memoryStyle = outreg, arch = Arch.Seed)) should include("4096 rows")
    // The stream's memory holds two banks of the capacity.
    rejection(AccelParams(m = 2, capacity = 2048, arch = Arch.Stream, memoryStyle = outreg)) should include("4096 rows")
    AccelParams(m = 2, capacity = 1024, arch = Arch.Stream, memoryStyle = outreg).memoryRows shouldBe 2048
    AccelParams(m = 2, capacity = 4096, memoryStyle = outreg, arch = Arch.Seed).memoryRows shouldBe 2048 // rows per lane
    MemoryStyle.fromName("ecp5-outreg") shouldBe outreg
    intercept[IllegalArgumentException](MemoryStyle.fromName("outreg")).getMessage should include("inferred, ecp5-outreg")
  }

  it should "reject a batch queue of no cells, and size the cell tag for the queue" in {
    rejection(AccelParams(batchCells = 0)) should include("batchCells")
    AccelParams(batchCells = 64).cellTagWidth shouldBe 6 // tags 0..63
    AccelParams(batchCells = 5).cellTagWidth shouldBe 3
    AccelParams(batchCells = 1).cellTagWidth shouldBe 1
  }

  it should "count every register of the pipeline in its latency" in {
    // Seed: memory read, output registers, rotator, comparator, AND.
    AccelParams(memoryOutputStages = 0, arch = Arch.Seed).pipelineLatency shouldBe 4
    AccelParams(arch = Arch.Seed).pipelineLatency shouldBe 6
    // Stream: the lanes' two cycles of lag, comparator, AND; the memory's registers are in the startup.
    AccelParams(memoryOutputStages = 0).pipelineLatency shouldBe 4
    AccelParams().pipelineLatency shouldBe 4
    AccelParams().startupLatency shouldBe AccelParams().readLatency
    AccelParams(arch = Arch.Seed).startupLatency shouldBe 0
  }

  it should "reject a result queue too shallow to keep the pipeline streaming" in {
    rejection(AccelParams(resultQueueDepth = 2)) should include("resultQueueDepth")
  }

  it should "size indices and counts for the capacity" in {
    val p = AccelParams(m = 3, capacity = 24, arch = Arch.Seed)
    p.indexWidth shouldBe 5 // 0..23
    p.countWidth shouldBe 5 // 0..24
    p.depth shouldBe 8
    AccelParams(m = 4, capacity = 32).countWidth shouldBe 6 // 32 needs six bits
  }

  it should "default to 256 rows per seed memory, and to 2048 objects for the stream at any m" in {
    Arch.Seed.defaultCapacity(13) shouldBe 13 * 256
    Arch.Stream.defaultCapacity(13) shouldBe 2048
    AccelParams().capacity shouldBe AccelParams().arch.defaultCapacity(AccelParams().m)
    AccelParams().capacity shouldBe Arch.Seed.defaultCapacity(AccelParams().m)
  }

  it should "default to what the Makefile builds" in {
    // `make verilog`, `make host` and `make fpga` pass ARCH and M; a capacity only when given.
    val makefile = scala.io.Source.fromFile("Makefile").getLines().toSeq
    def default(variable: String): String =
      makefile.collectFirst { case l if l.matches(s"$variable\\s*\\?=.*") => l.split("\\?=", 2)(1).trim }
        .getOrElse(fail(s"no '$variable ?=' in the Makefile"))
    default("ARCH") shouldBe AccelParams().arch.name
    default("M") shouldBe AccelParams().m.toString
    default("KEY_WIDTH") shouldBe AccelParams().keyWidth.toString
    default("CAPACITY") shouldBe empty
  }

  "The C header" should "carry the parameters the host must agree with" in {
    val p = AccelParams(m = 5, capacity = 40, arch = Arch.Seed)
    val h = CHeader(p)
    h should include("#define BPACCEL_M 5")
    h should include("#define BPACCEL_CAPACITY 40")
    h should include("#define BPACCEL_KEY_WIDTH 32")
    h should include(s"#define BPACCEL_RUN_OVERHEAD_CYCLES ${p.runOverheadCycles}")
    h should include("#define BPACCEL_READ_LATENCY 0")
    h should include("#define BPACCEL_ERROR_LOAD_OVERFLOW 3")
    h should include("#define BPACCEL_BATCH_CELLS 64")
    h should include("#define BPACCEL_CELL_TAG_WIDTH 6")
  }

  "The parameter file" should "hold every value of the C header, and name the memories the Verilog has" in {
    for (p <- Seq(AccelParams(m = 5, capacity = 40, arch = Arch.Seed), AccelParams(m = 3, capacity = 25, keyWidth = 16)))
      withClue(s"$p: ") {
        val json   = ujson.read(ParamsJson(p)).obj
        val header = """(?m)^#define BPACCEL_(\w+) (.*)$""".r.findAllMatchIn(CHeader(p)).map(x => x.group(1) -> x.group(2)).toMap
        json("schema").str shouldBe ParamsJson.schema
        val values = json.toSeq.collect {
          case (k, ujson.Num(v))  => k.toUpperCase -> v.toLong.toString
          case (k, ujson.Bool(v)) => k.toUpperCase -> (if (v) "1" else "0")
          case (k, ujson.Str(v)) if k != "schema" => k.toUpperCase -> s"\"$v\""
        } ++ json("errors").obj.toSeq.map { case (k, v) => s"ERROR_${k.toUpperCase}" -> v.num.toLong.toString }
        values.toMap shouldBe header - "PARAMS_H"
        json("arch").str shouldBe p.arch.name
        json("memory_count").num shouldBe p.memoryCount
        json("memory_module").str shouldBe p.memoryStyle.moduleName(p.memoryRows, p.memoryWidth)
      }
    AccelParams(m = 5, capacity = 40, arch = Arch.Seed).memoryCount shouldBe 30 // six striped memories per lane
    AccelParams(m = 5, capacity = 40).memoryCount shouldBe 1
  }
}
