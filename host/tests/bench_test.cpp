#include <gtest/gtest.h>

#include <random>

#include "benchmark.hpp"
#include "exact_pairs.hpp"
#include "scene.hpp"
#include "scenes.hpp"

using namespace bpaccel;

namespace {

BenchConfig tinyConfig() {
  BenchConfig c;
  c.objectCounts = {30, 60};
  c.cellSizes = {std::nullopt, 4, 16};
  c.frames = 3;
  c.warmup = 1;
  c.accelBackend = "rtl";
  return c;
}

}  // namespace

TEST(ExactPairs, MatchesBruteForceOnAdversarialScenes) {
  for (const auto& [name, boxes] : bpaccel::testing::adversarialScenes(300, 4)) {
    std::vector<Pair> pairs;
    exactPairs(boxes, pairs);
    EXPECT_EQ(pairs, bpaccel::testing::bruteForce(boxes)) << name;
  }
}

TEST(Scene, KeepsObjectsMovingInsideTheCube) {
  SceneConfig sc;
  sc.objects = 50;
  BouncingCubeScene scene(sc);
  const double e0 = scene.kineticEnergy();
  for (int f = 0; f < 120; ++f) scene.step();
  std::vector<Aabb> boxes;
  scene.aabbs(boxes);
  ASSERT_EQ(boxes.size(), 50u);
  for (const auto& b : boxes)
    for (int a = 0; a < 3; ++a) {
      EXPECT_GT(b.max[a], -0.5f);
      EXPECT_LT(b.min[a], scene.cubeEdge() + 0.5f);
    }
  // Elastic contacts and walls: the objects still move after two seconds.
  EXPECT_GT(scene.kineticEnergy(), 0.3 * e0);
}

TEST(Scene, RejectsImpossibleParameters) {
  SceneConfig sc;
  sc.objects = 10;
  sc.density = 50;  // a cube far too small for the objects
  EXPECT_THROW(BouncingCubeScene{sc}, std::invalid_argument);
}

TEST(Benchmark, ProducesEveryFieldAndATableOnATinyScene) {
  Benchmark bench(tinyConfig(), [](const std::string&) {});
  const auto j = bench.run();
  for (const char* key : {"configuration", "machine", "rows", "validation", "notes"}) EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["configuration"]["clock_hz"], 100e6);
  ASSERT_EQ(j["rows"].size(), 2u);
  for (const auto& row : j["rows"]) {
    EXPECT_TRUE(row.contains("exact_pairs_per_frame_mean"));
    ASSERT_EQ(row["methods"].size(), 3u + 3u + 3u);  // three Bullet broad phases, accelerator and cpu per cell size
    for (const auto& m : row["methods"]) {
      EXPECT_GT(m["frame_ms"]["median"].get<double>(), 0) << m["name"];
      EXPECT_EQ(m["missing_pairs"], 0) << m["name"];
      EXPECT_EQ(m["acceleration_over"].size(), 3u);
      if (m["kind"] == "accelerator")
        for (const char* part : {"host_ms_measured", "device_ms_modelled", "transfer_ms_modelled", "cycles", "runs"})
          EXPECT_TRUE(m.contains(part)) << part;
    }
  }
  const std::string table = Benchmark::table(j);
  EXPECT_NE(table.find("btDbvtBroadphase"), std::string::npos);
  EXPECT_NE(table.find("accelerator k-d 16"), std::string::npos);
  EXPECT_NE(table.find("Acceleration over bt32BitAxisSweep3"), std::string::npos);
}

TEST(Benchmark, FailsLoudlyWhenTheAcceleratorMissesAPair) {
  auto config = tinyConfig();
  config.tamper = [](std::vector<Pair>& pairs) {
    if (!pairs.empty()) pairs.pop_back();
  };
  Benchmark bench(config, [](const std::string&) {});
  EXPECT_THROW(bench.run(), ValidationFailure);
}

TEST(Benchmark, FailsLoudlyWhenTheAcceleratorInventsAPair) {
  auto config = tinyConfig();
  config.tamper = [](std::vector<Pair>& pairs) { pairs.emplace_back(0, 1000000); };
  Benchmark bench(config, [](const std::string&) {});
  EXPECT_THROW(bench.run(), ValidationFailure);
}

TEST(CompareSorted, CountsMissingAndExtraPairs) {
  const std::vector<Pair> exact = {{0, 1}, {0, 2}, {3, 4}};
  const std::vector<Pair> got = {{0, 1}, {1, 2}, {3, 4}, {5, 6}};
  const auto d = compareSorted(got, exact);
  EXPECT_EQ(d.missing, 1u);
  EXPECT_EQ(d.extra, 2u);
}

TEST(LinkModel, ChargesBytesAndLatencyPerRun) {
  LinkModel link{1e9, 2e-6};
  RunStats s;
  s.runs = 3;
  s.boxesSent = 1000;
  s.beatsReceived = 500;
  EXPECT_DOUBLE_EQ(link.seconds(s, 4), 3 * 2e-6 + (24000.0 + 2000.0) / 1e9);
}
