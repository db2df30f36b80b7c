package bpaccel.shell

import chisel3._
import chisel3.util._

/** Packs a reply into beats: records as a stream of words, then the
  * trailer on a fresh beat (the words between are zero), TLAST on its last.
  *
  * The records' words gather in a buffer of k + recordWords words; a beat
  * leaves when k are there. A trailer is taken only when no record is
  * offered (an adapter offers its summary after its last record): the
  * partial beat, if any, leaves padded with zeros, then the trailer's beats.
  */
class ReplyPacker(p: ShellParams, recordWords: Int) extends Module {
  private val k    = p.wordsPerBeat
  private val size = k + recordWords
  require(Protocol.TrailerWords % k == 0, "the trailer fills whole beats")
  private val trailerBeats = Protocol.TrailerWords / k
  val io = IO(new Bundle {
    val records = Flipped(Decoupled(new RecordWords(recordWords)))
    val trailer = Flipped(Decoupled(Vec(Protocol.TrailerWords, UInt(32.W))))
    val out     = Decoupled(new OutputBeat(p.streamBits))
  })
  val buffer = RegInit(VecInit(Seq.fill(size)(0.U(32.W))))
  val count  = RegInit(0.U(log2Ceil(size + 1).W))
  val trailer     = Reg(Vec(Protocol.TrailerWords, UInt(32.W)))
  val sending     = RegInit(false.B) // the trailer is being sent
  val trailerBeat = RegInit(0.U(log2Ceil(trailerBeats).max(1).W))

  // A full beat of records, or the last partial one before the trailer, or a trailer beat.
  val fullBeat    = count >= k.U
  val partialBeat = !fullBeat && count =/= 0.U && io.trailer.valid && !io.records.valid && !sending
  val beatWords   = VecInit(buffer.take(k).zipWithIndex.map { case (word, i) => Mux(i.U < count, word, 0.U) })
  val trailerWords = VecInit.tabulate(k)(i => VecInit.tabulate(trailerBeats)(b => trailer(b * k + i))(trailerBeat))
  io.out.valid        := sending || fullBeat || partialBeat
  io.out.bits.data    := Mux(sending, trailerWords, beatWords).asUInt
  io.out.bits.trailer := sending
  io.out.bits.last    := sending && trailerBeat === (trailerBeats - 1).U
  val emitted = io.out.fire && !sending
  val left    = Mux(emitted, Mux(fullBeat, count - k.U, 0.U), count)

  // Records join behind what stays.
  // Room for the longest record: a test on `left` alone.
  io.records.ready := !sending && left <= (size - recordWords).U
  for (j <- 0 until size) {
    val kept = if (j + k < size) Mux(emitted, buffer(j + k), buffer(j)) else Mux(emitted, 0.U, buffer(j))
    val fromRecord = VecInit.tabulate(recordWords)(i => io.records.bits.words(i))
    val slot = j.U -& left
    buffer(j) := Mux(io.records.fire && j.U >= left && slot < io.records.bits.count, fromRecord(slot(log2Ceil(recordWords.max(2)) - 1, 0)), kept)
  }
  count := left + Mux(io.records.fire, io.records.bits.count, 0.U)

  io.trailer.ready := !sending && count === 0.U && !io.records.valid
  when(io.trailer.fire) {
    trailer     := io.trailer.bits
    sending     := true.B
    trailerBeat := 0.U
  }
  when(sending && io.out.fire) {
    trailerBeat := trailerBeat + 1.U
    when(io.out.bits.last) { sending := false.B }
  }
}
