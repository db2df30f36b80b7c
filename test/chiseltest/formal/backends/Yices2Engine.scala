package chiseltest.formal.backends

/** ChiselTest 6.0.0 implements a Yices 2 engine but keeps its annotation private
  * to this package; this names it for bpaccel.FormalSolver.
  */
object Yices2Engine {
  val annotation: FormalEngineAnnotation = Yices2EngineAnnotation
}
