// Chisel generator for the all-pairs AABB broad-phase accelerator.
// Sources live in src/ and tests in test/ (not sbt's default layout) so the
// repository's top level reads as src/, test/, host/, scripts/.
ThisBuild / scalaVersion := "2.13.14"
ThisBuild / version      := "0.1.0"

val chiselVersion = "6.6.0"

lazy val root = (project in file("."))
  .settings(
    name := "bpaccel",
    libraryDependencies ++= Seq(
      "org.chipsalliance" %% "chisel"     % chiselVersion,
      "com.github.scopt"  %% "scopt"      % "4.1.0",
      "edu.berkeley.cs"   %% "chiseltest" % "6.0.0" % Test,
      "org.scalatestplus" %% "scalacheck-1-17" % "3.2.17.0" % Test
    ),
    addCompilerPlugin("org.chipsalliance" % "chisel-plugin" % chiselVersion cross CrossVersion.full),
    scalacOptions ++= Seq(
      "-language:reflectiveCalls",
      "-deprecation",
      "-feature",
      "-Xcheckinit",
      "-Ymacro-annotations"
    ),
    Compile / scalaSource := baseDirectory.value / "src",
    Test / scalaSource    := baseDirectory.value / "test",
    // Simulations are CPU-bound; the machine has two cores.
    Test / parallelExecution := true,
    Test / testForkedParallel := true,
    concurrentRestrictions in Global += Tags.limit(Tags.Test, 2),
    Test / fork := true,
    Test / javaOptions ++= Seq("-Xmx6g", "-Xss16m"),
    // The formal checks' solvers, Yices and z3 (scripts/deps.sh installs them there), before any other.
    Test / envVars += "PATH" -> s"${(baseDirectory.value / "build" / "formal-tools" / "bin").getAbsolutePath}:${sys.env.getOrElse("PATH", "")}",
    // Each Verilator-backed configuration compiles Verilator's runtime (about
    // 8 of a small model's 11 s); through ccache (scripts/deps.sh installs it)
    // and scripts/verilator-objcache, which keeps the design's header out of
    // the runtime's compile, the run compiles it once for all configurations.
    Test / envVars ++= (
      if (new File("/usr/bin/ccache").exists)
        Map(
          "OBJCACHE"       -> (baseDirectory.value / "scripts" / "verilator-objcache").getAbsolutePath,
          "CCACHE_DIR"     -> (baseDirectory.value / "build" / "ccache").getAbsolutePath,
          // Paths relative to here, so each configuration's directory hits the same entries.
          "CCACHE_BASEDIR" -> baseDirectory.value.getAbsolutePath
        )
      else Map.empty[String, String]
    ),
    // The specs' simulations are short: their models are compiled at -O0 in
    // place of Verilator's -Os, in about half the time, and by clang++ where
    // it is installed (scripts/deps.sh installs it for the fuzz targets), in
    // about three quarters of g++'s CPU time (make reads these as command-line variables).
    Test / envVars += "MAKEFLAGS" -> ("OPT_FAST=-O0 OPT_SLOW=-O0" +
      (if (new File("/usr/bin/clang++").exists) " CXX=clang++ LINK=clang++" else "")),
    // The deep formal checks (tag bpaccel.FormalLong) run only with BPACCEL_FORMAL_LONG set: make formal-long.
    Test / testOptions ++= (
      if (sys.env.contains("BPACCEL_FORMAL_LONG")) Nil
      else Seq(Tests.Argument(TestFrameworks.ScalaTest, "-l", "bpaccel.FormalLong"))
    ),
    Compile / run / fork := true,
    Compile / run / javaOptions ++= Seq("-Xmx6g", "-Xss16m")
  )
