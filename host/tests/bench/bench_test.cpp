#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sys/wait.h>
#include <utility>

#include "device/model_backend.hpp"
#include "device/built_device.hpp"
#include "device/backend.hpp"
#include "benchmark.hpp"
#include "rtl_device.hpp"
#include "bpaccel_params.h"
#include "peers/bullet_methods.hpp"
#include "scenes/exact_pairs.hpp"
#include "peers/fcl_managers.hpp"
#include "peers/ode_spaces.hpp"
#include "device/rtl/rtl_backend.hpp"
#include "scenes/scene.hpp"
#include "scenes.hpp"
#include "scenes/step_timing.hpp"

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>

using namespace bpaccel;

namespace {

BenchConfig tinyConfig() {
  BenchConfig c;
  c.objectCounts = {30, 60};
  c.frames = 3;
  c.warmup = 1;
  return c;
}

LineUpConfig tinyLineUp() {
  LineUpConfig l;
  l.cellSizes = {std::nullopt, 4, 16};
  l.gridCellSizes = {16};
  l.device = rtlDevice();
  return l;
}

nlohmann::json runQuietly(const BenchConfig& config, std::vector<MethodSpec> lineUp, const LineUpConfig& l) {
  Benchmark bench(config, std::move(lineUp), describe(l), [](const std::string&) {});
  return bench.run();
}

// Decorates a method: its pairs pass through `edit` before validation.
class Tampered final : public TimedMethod {
 public:
  Tampered(std::unique_ptr<TimedMethod> inner, std::function<void(std::vector<Pair>&)> edit)
      : inner_(std::move(inner)), edit_(std::move(edit)) {}
  void update(std::span<const Aabb> boxes) override { inner_->update(boxes); }
  void pairs(std::vector<Pair>& out) override {
    inner_->pairs(out);
    edit_(out);
  }
  FrameTime frameTime(double s) const override { return inner_->frameTime(s); }
  bool hasPacedRun() const override { return inner_->hasPacedRun(); }
  void readyPacedDevice() override { inner_->readyPacedDevice(); }
  void runPaced(std::span<const Aabb> boxes) override { inner_->runPaced(boxes); }

 private:
  std::unique_ptr<TimedMethod> inner_;
  std::function<void(std::vector<Pair>&)> edit_;
};

// Decorates a method: the pairs of its paced runs only pass through `edit`.
class TamperedPaced final : public TimedMethod {
 public:
  TamperedPaced(std::unique_ptr<TimedMethod> inner, std::function<void(std::vector<Pair>&)> edit)
      : inner_(std::move(inner)), edit_(std::move(edit)) {}
  void update(std::span<const Aabb> boxes) override {
    paced_ = false;
    inner_->update(boxes);
  }
  void pairs(std::vector<Pair>& out) override {
    inner_->pairs(out);
    if (paced_) edit_(out);
  }
  FrameTime frameTime(double s) const override { return inner_->frameTime(s); }
  bool hasPacedRun() const override { return inner_->hasPacedRun(); }
  void readyPacedDevice() override { inner_->readyPacedDevice(); }
  void runPaced(std::span<const Aabb> boxes) override {
    paced_ = true;
    inner_->runPaced(boxes);
  }

 private:
  std::unique_ptr<TimedMethod> inner_;
  std::function<void(std::vector<Pair>&)> edit_;
  bool paced_ = false;
};

// The rtl device, batched 8 cells a hand-over, each frame also run paced.
std::shared_ptr<DeviceConfig> pacedRtlDevice() {
  auto d = rtlDevice();
  d->cellsPerBatch = 8;
  d->paced = true;
  return d;
}

std::vector<MethodSpec> tamperedAccelerator(std::function<void(std::vector<Pair>&)> edit) {
  auto specs = acceleratorMethods(rtlDevice(), {16}, 1e8);
  auto make = specs[0].make;
  specs[0].make = [make, edit](const SceneStart& s) { return std::make_unique<Tampered>(make(s), edit); };
  return specs;
}

// A peer with a fixed frame time, exact or missing one pair a frame, that logs when it runs.
class FakePeer final : public TimedMethod {
 public:
  FakePeer(int id, double seconds, bool dropOne, std::vector<int>* log)
      : id_(id), seconds_(seconds), dropOne_(dropOne), log_(log) {}
  void update(std::span<const Aabb> boxes) override {
    sortAndSweepPairs(boxes, pairs_);
    if (dropOne_ && !pairs_.empty()) pairs_.pop_back();
    if (log_) log_->push_back(id_);
  }
  void pairs(std::vector<Pair>& out) override { out = pairs_; }
  FrameTime frameTime(double) const override { return {seconds_, std::nullopt}; }

 private:
  int id_;
  double seconds_;
  bool dropOne_;
  std::vector<int>* log_;
  std::vector<Pair> pairs_;
};

MethodSpec fakePeer(int id, double seconds, bool dropOne, std::vector<int>* log = nullptr) {
  MethodSpec s;
  s.name = "fake " + std::to_string(id);
  s.kind = MethodKind::Peer;
  s.library = "Fake";
  s.make = [=](const SceneStart&) { return std::make_unique<FakePeer>(id, seconds, dropOne, log); };
  return s;
}

}  // namespace

TEST(ExactPairs, MatchesBruteForceOnAdversarialScenes) {
  for (const auto& [name, boxes] : bpaccel::testing::adversarialScenes(300, 4)) {
    std::vector<Pair> grid, sweep;
    exactPairs(boxes, grid);
    sortAndSweepPairs(boxes, sweep);
    const auto brute = bpaccel::testing::bruteForce(boxes);
    EXPECT_EQ(grid, brute) << name;
    EXPECT_EQ(sweep, brute) << name;
  }
}

TEST(ExactPairs, GridFindsPairsAcrossCellBoundariesOfABouncingScene) {
  SceneConfig sc;
  sc.objects = 3000;
  BouncingCubeScene scene(sc);
  for (int f = 0; f < 3; ++f) scene.step();
  std::vector<Aabb> boxes;
  scene.aabbs(boxes);
  std::vector<Pair> grid;
  exactPairs(boxes, grid);
  EXPECT_GT(grid.size(), 100u);
  EXPECT_EQ(grid, bpaccel::testing::bruteForce(boxes));
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

TEST(Benchmark, RunsEveryMethodOfTheLineUpAndWritesEveryField) {
  const auto l = tinyLineUp();
  const auto j = runQuietly(tinyConfig(), standardLineUp(l), l);
  for (const char* key : {"configuration", "machine", "rows", "validation", "notes"}) EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["configuration"]["clock_hz"], 100e6);
  ASSERT_EQ(j["rows"].size(), 2u);
  std::set<std::string> kinds, libraries;
  for (const auto& row : j["rows"]) {
    EXPECT_TRUE(row.contains("exact_pairs_per_frame_mean"));
    EXPECT_FALSE(row["fastest_baseline"].is_null());
    // Bullet 3, FCL 5 (the tree in three usages), CGAL 1, ODE 2, then accelerator and cpu per cell size, k-d
    // and grid, cpu auto and bpaccel::BroadPhaseManager.
    ASSERT_EQ(row["methods"].size(), 3u + 5u + 1u + 2u + (3u + 1u) + (3u + 1u) + 1u + 1u);
    std::set<std::string> gridRows;
    for (const auto& m : row["methods"])
      if (m.value("partition", "") == "grid") gridRows.insert(m["name"]);
    EXPECT_EQ(gridRows,
              (std::set<std::string>{"accelerator grid 16", "cpu grid 16", "bpaccel::BroadPhaseManager, cpu grid 64"}));
    for (const auto& m : row["methods"]) {
      kinds.insert(m["kind"]);
      libraries.insert(m["library"]);
      ASSERT_FALSE(m.contains("skipped")) << m["name"];
      EXPECT_GT(m["frame_ms"]["median"].get<double>(), 0) << m["name"];
      EXPECT_TRUE(m["missing_pairs"].is_number() && m["extra_pairs"].is_number()) << m["name"];
      if (m["kind"] == "accelerator" || m["kind"] == "cpu") EXPECT_EQ(m["missing_pairs"], 0) << m["name"];
      EXPECT_EQ(m["acceleration_over"].size(), 11u);
      if (m["kind"] == "accelerator")
        for (const char* part : {"host_ms_measured", "host_partition_ms_measured", "device_ms_modelled",
                                 "transfer_ms_modelled", "device_cycles",
                                 "load_cycles", "runs", "batches", "serial_frame_ms", "pipelined_frame_ms_modelled"})
          EXPECT_TRUE(m.contains(part)) << part;
      if (m["kind"] == "accelerator") {
        // Overlapping can hide host and link time, never the device's own busy cycles.
        EXPECT_GE(m["pipelined_frame_ms_modelled"]["median"].get<double>() * (1 + 1e-9),
                  m["device_ms_modelled"]["min"].get<double>())
            << m["name"];
        EXPECT_EQ(m["serial_frame_ms"], m["frame_ms"]) << m["name"];
        // The partition is a part of the host's work, and only rows with a cell size build one.
        const double partition = m["host_partition_ms_measured"]["median"].get<double>();
        EXPECT_LE(partition, m["host_ms_measured"]["median"].get<double>()) << m["name"];
        if (m["cell_size"] == "none")
          EXPECT_EQ(partition, 0) << m["name"];
        else
          EXPECT_GT(partition, 0) << m["name"];
      }
    }
    // The timeline of the row's best accelerator method: one device span per hand-over.
    const auto& tl = row["timeline"];
    ASSERT_TRUE(tl.is_object());
    EXPECT_EQ(tl["lanes"]["device"].size(), tl["batches"].get<std::size_t>());
    EXPECT_GT(tl["frame_ms"].get<double>(), 0);
    for (const char* lane : {"produce", "link", "device", "decode"}) EXPECT_TRUE(tl["lanes"].contains(lane)) << lane;
  }
  EXPECT_EQ(kinds, (std::set<std::string>{"bullet", "peer", "accelerator", "cpu"}));
  EXPECT_EQ(libraries, (std::set<std::string>{"Bullet 3.24", "FCL 0.7", "CGAL 5.5", "ODE 0.16", "bpaccel"}));
  const std::string table = Benchmark::table(j);
  for (const char* s : {"btDbvtBroadphase", "FCL DynamicAABBTree", "CGAL box_self_intersection_d", "ODE dHashSpace",
                        "accelerator k-d 16", "Acceleration over the FASTEST", "Acceleration over the fastest of FCL 0.7",
                        "MODELLED schedule", "median of the first tenth"})
    EXPECT_NE(table.find(s), std::string::npos) << s;
}

TEST(Benchmark, EveryFclUsageIsValidatedAndABrokenFclManagerOfOursFailsTheRun) {
  LineUpConfig l;
  auto lineUp = fclMethods(1e9);
  lineUp.push_back(bpaccelFclMethod(16));
  const auto j = runQuietly(tinyConfig(), lineUp, l);
  for (const auto& row : j["rows"])
    for (const auto& m : row["methods"]) {
      EXPECT_EQ(m["missing_pairs"], 0) << m["name"];
      for (const char* tenth : {"first_tenth", "last_tenth"}) EXPECT_TRUE(m["frame_ms"].contains(tenth)) << tenth;
    }
  auto broken = bpaccelFclMethod(16);
  auto make = broken.make;
  broken.make = [make](const SceneStart& s) {
    return std::make_unique<Tampered>(make(s), [](std::vector<Pair>& p) {
      if (!p.empty()) p.pop_back();
    });
  };
  try {
    runQuietly(tinyConfig(), {broken}, l);
    FAIL() << "no ValidationFailure";
  } catch (const ValidationFailure& e) {
    EXPECT_EQ(e.method(), "bpaccel::BroadPhaseManager, cpu grid 16");
    EXPECT_EQ(e.difference().missing, 1u);
  }
}

TEST(Benchmark, EveryAcceleratorRowNamesTheProfileItIsModelledOn) {
  auto l = tinyLineUp();
  const ProfileInputs in{.device = {8, "stream", 32}, .fpgaDir = "/nonexistent", .lfe5uReport = ""};
  l.profiles = {ecp5FiveGProfile(in), gen3x8Profile(in)};
  auto config = tinyConfig();
  config.objectCounts = {30};
  config.frames = 1;
  config.warmup = 0;
  const auto j = runQuietly(config, standardLineUp(l), l);
  ASSERT_EQ(j["configuration"]["profiles"].size(), 2u);
  EXPECT_EQ(j["configuration"]["profiles"][0]["name"], "ecp5-5g");
  EXPECT_FALSE(j["configuration"].contains("clock_hz"));  // no clock but the profiles'
  std::map<std::string, std::size_t> perProfile;
  for (const auto& m : j["rows"][0]["methods"]) {
    if (m["kind"] != "accelerator") {
      EXPECT_FALSE(m.contains("profile")) << m["name"];
      continue;
    }
    ASSERT_TRUE(m.contains("profile")) << m["name"];
    const std::string profile = m["profile"]["name"];
    const std::string name = m["name"];
    EXPECT_EQ(name.substr(name.size() - profile.size() - 4), " on " + profile) << name;
    for (const char* field : {"part", "link", "summary"}) EXPECT_TRUE(m["profile"].contains(field)) << field;
    EXPECT_EQ(m["profile"]["part"]["clock_hz"]["provenance"], "assumed") << name;  // no report at all here
    if (!m.contains("skipped")) EXPECT_EQ(m["missing_pairs"], 0) << name;
    ++perProfile[profile];
  }
  // k-d none, 4, 16, grid 16 and binning on each.
  EXPECT_EQ(perProfile, (std::map<std::string, std::size_t>{{"ecp5-5g", 5}, {"gen3x8", 5}}));
  // The slower link costs more transfer time for the same frame.
  const auto transfer = [&](const std::string& name) {
    for (const auto& m : j["rows"][0]["methods"])
      if (m["name"] == name) return m["transfer_ms_modelled"]["median"].get<double>();
    return -1.0;
  };
  EXPECT_GT(transfer("accelerator k-d 16 on ecp5-5g"), transfer("accelerator k-d 16 on gen3x8"));
  const std::string table = Benchmark::table(j);
  EXPECT_NE(table.find("accelerator k-d 16 on gen3x8"), std::string::npos);
  EXPECT_NE(table.find("profile ecp5-5g: LFE5UM5G-85F speed 8"), std::string::npos) << table;
}

TEST(Benchmark, AnExactMethodThatMissesAPairFailsTheRunWithTheCount) {
  const auto l = tinyLineUp();
  try {
    runQuietly(tinyConfig(), tamperedAccelerator([](std::vector<Pair>& p) {
                 if (!p.empty()) p.pop_back();
               }),
               l);
    FAIL() << "no ValidationFailure";
  } catch (const ValidationFailure& e) {
    EXPECT_EQ(e.method(), "accelerator k-d 16");
    EXPECT_EQ(e.difference().missing, 1u);
    EXPECT_EQ(e.difference().extra, 0u);
  }
}

TEST(Benchmark, AnExactMethodThatInventsAPairFailsTheRunWithTheCount) {
  const auto l = tinyLineUp();
  try {
    runQuietly(tinyConfig(), tamperedAccelerator([](std::vector<Pair>& p) { p.emplace_back(0, 1000000); }), l);
    FAIL() << "no ValidationFailure";
  } catch (const ValidationFailure& e) {
    EXPECT_EQ(e.difference().missing, 0u);
    EXPECT_EQ(e.difference().extra, 1u);
  }
}

TEST(Benchmark, PacedRunsAreTimedValidatedAndReportedBesideTheModelledFrame) {
  LineUpConfig l;
  l.cellSizes = {16};
  l.gridCellSizes = {16};
  l.device = pacedRtlDevice();
  const auto j = runQuietly(tinyConfig(), standardLineUp(l), l);
  std::size_t paced = 0;
  for (const auto& row : j["rows"]) {
    for (const auto& m : row["methods"]) {
      if (m["kind"] != "accelerator") {
        EXPECT_FALSE(m.contains("paced_frame_ms")) << m["name"];
        continue;
      }
      ASSERT_TRUE(m.contains("paced_frame_ms")) << m["name"];
      EXPECT_GT(m["paced_frame_ms"]["median"].get<double>(), 0) << m["name"];
      // It waits for the device it emulates: never less than the device's modelled busy time.
      EXPECT_GE(m["paced_frame_ms"]["min"].get<double>() * (1 + 1e-9), m["device_ms_modelled"]["min"].get<double>())
          << m["name"];
      EXPECT_TRUE(m["paced_acceleration_over_fastest_baseline"].is_number()) << m["name"];
      ++paced;
    }
    EXPECT_TRUE(row["timeline"]["paced_ms"].is_number());
  }
  EXPECT_EQ(paced, 4u);  // k-d 16 and grid 16, two rows
  const std::string table = Benchmark::table(j);
  EXPECT_NE(table.find("against a device EMULATED for its modelled time"), std::string::npos);

  // Without paced runs, no such figure and no such block.
  auto unpaced = pacedRtlDevice();
  unpaced->paced = false;
  l.device = unpaced;
  const auto plain = runQuietly(tinyConfig(), standardLineUp(l), l);
  for (const auto& m : plain["rows"][0]["methods"]) EXPECT_FALSE(m.contains("paced_frame_ms")) << m["name"];
  EXPECT_EQ(Benchmark::table(plain).find("EMULATED"), std::string::npos);
}

TEST(Benchmark, APacedRunThatMissesAPairFailsTheRunNamingThePacedRun) {
  const auto l = tinyLineUp();
  auto specs = acceleratorMethods(pacedRtlDevice(), {16}, 1e8);
  auto make = specs[0].make;
  specs[0].make = [make](const SceneStart& s) {
    return std::make_unique<TamperedPaced>(make(s), [](std::vector<Pair>& p) {
      if (!p.empty()) p.pop_back();
    });
  };
  try {
    runQuietly(tinyConfig(), specs, l);
    FAIL() << "no ValidationFailure";
  } catch (const ValidationFailure& e) {
    EXPECT_EQ(e.method(), "accelerator k-d 16 (paced run)");
    EXPECT_EQ(e.difference().missing, 1u);
  }
}

TEST(AcceleratorMethod, APacedRunFindsTheUpdatesPairsAndNeedsBatches) {
  const auto boxes = bpaccel::testing::adversarialScenes(1500, 5)[0].second;
  auto d = std::make_shared<DeviceConfig>();
  d->makeBackend = [] { return std::make_unique<ModelBackend>(builtDeviceParams()); };
  d->cellsPerBatch = 8;
  d->paced = true;
  AcceleratorMethod method(d, 16, PartitionKind::UniformGrid);
  ASSERT_TRUE(method.hasPacedRun());
  std::vector<Pair> serial, paced;
  for (int frame = 0; frame < 2; ++frame) {
    method.update(boxes);
    method.pairs(serial);
    method.readyPacedDevice();
    method.runPaced(boxes);
    method.pairs(paced);
    EXPECT_EQ(bpaccel::testing::sorted(paced), bpaccel::testing::sorted(serial));
    EXPECT_EQ(bpaccel::testing::sorted(paced), bpaccel::testing::bruteForce(boxes));
  }
  d->paced = false;
  AcceleratorMethod plain(d, 16);
  EXPECT_FALSE(plain.hasPacedRun());
  EXPECT_THROW(plain.runPaced(boxes), std::logic_error);
  d->paced = true;
  d->cellsPerBatch = 1;  // one cell a hand-over: nothing to run asynchronously
  EXPECT_THROW(AcceleratorMethod(d, 16), std::invalid_argument);
}

TEST(Benchmark, APeerThatMissesPairsIsCountedAndMarkedNotFailed) {
  LineUpConfig l;
  auto config = tinyConfig();
  const auto j = runQuietly(config, {fakePeer(0, 1e-3, false), fakePeer(1, 1e-3, true)}, l);
  for (const auto& row : j["rows"]) {
    const auto& exact = row["methods"][0];
    const auto& inexact = row["methods"][1];
    EXPECT_EQ(exact["missing_pairs"], 0);
    EXPECT_EQ(inexact["missing_pairs"], config.frames + config.warmup);  // one a frame, warm-up included
    EXPECT_FALSE(inexact["found_every_pair"].get<bool>());
  }
  const std::string table = Benchmark::table(j);
  EXPECT_NE(table.find("fake 1: extra 0, duplicates 0, missing 4  <-- INEXACT"), std::string::npos) << table;
  EXPECT_NE(table.find("!"), std::string::npos);
}

TEST(Benchmark, TheHeadlineIsOverTheFastestBaselineThatFoundEveryPair) {
  LineUpConfig l;
  auto lineUp = std::vector<MethodSpec>{fakePeer(0, 3e-3, false), fakePeer(1, 1e-3, true), fakePeer(2, 2e-3, false)};
  lineUp.push_back(cpuMethods({4}, 1e8)[0]);
  const auto j = runQuietly(tinyConfig(), lineUp, l);
  for (const auto& row : j["rows"]) {
    EXPECT_EQ(row["fastest_baseline"]["name"], "fake 2");  // fake 1 is faster but missed pairs
    EXPECT_DOUBLE_EQ(row["fastest_baseline"]["frame_ms"].get<double>(), 2.0);
    EXPECT_EQ(row["fastest_per_library"]["Fake"]["name"], "fake 1");
    const auto& slow = row["methods"][0];
    EXPECT_DOUBLE_EQ(slow["acceleration_over_fastest_baseline"].get<double>(), 2.0 / 3.0);
  }
}

TEST(Benchmark, SkippedMethodsAreListedWithTheirReason) {
  auto l = tinyLineUp();
  l.maxAllPairsTests = 500;  // n = 30: 435 tests run; n = 60: 1770 tests skip
  const auto j = runQuietly(tinyConfig(), standardLineUp(l), l);
  std::set<std::string> skipped;
  for (const auto& m : j["rows"][1]["methods"])
    if (m.contains("skipped")) {
      skipped.insert(m["name"]);
      EXPECT_NE(m["skipped"].get<std::string>().find("tests all pairs"), std::string::npos);
      EXPECT_TRUE(m["frame_ms"].is_null());
    }
  EXPECT_EQ(skipped, (std::set<std::string>{"btSimpleBroadphase", "accelerator k-d none", "cpu k-d none"}));
  for (const auto& m : j["rows"][0]["methods"]) EXPECT_FALSE(m.contains("skipped")) << m["name"];
  const std::string table = Benchmark::table(j);
  EXPECT_NE(table.find("n=60 btSimpleBroadphase: skipped: tests all pairs"), std::string::npos) << table;
}

TEST(Benchmark, TheAxisSweepIsSkippedWhereItsSetUpTakesMinutes) {
  EXPECT_FALSE(axisSweepSkipReason(50000).has_value());
  for (std::size_t n : {50001u, 100000u, 1000000u}) {
    const auto reason = axisSweepSkipReason(n);
    ASSERT_TRUE(reason.has_value()) << n;
    EXPECT_NE(reason->find("Theta(n^2)"), std::string::npos);
  }
}

TEST(Benchmark, OdesHashSpaceIsSkippedWhereItsPairTableOverflowsAnInt) {
  EXPECT_FALSE(hashSpaceSkipReason(100000).has_value());
  EXPECT_FALSE(hashSpaceSkipReason(131071).has_value());  // 131071 * 16384 bytes = INT_MAX - 16383
  for (std::size_t n : {131072u, 300000u, 1000000u}) {
    const auto reason = hashSpaceSkipReason(n);
    ASSERT_TRUE(reason.has_value()) << n;
    EXPECT_NE(reason->find("aborts"), std::string::npos) << *reason;
  }
}

TEST(Benchmark, PairsOverlappingOnXCountsEveryClosedOverlapOnce) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> coord(0, 12);  // a coarse grid: many shared end points
  for (int scene = 0; scene < 50; ++scene) {
    std::vector<Aabb> boxes(static_cast<std::size_t>(scene));
    for (Aabb& b : boxes) {
      const int a = coord(rng), c = coord(rng);
      b = Aabb{{float(std::min(a, c)), 0, 0}, {float(std::max(a, c)), 1, 1}};
    }
    std::uint64_t brute = 0;
    for (std::size_t i = 0; i < boxes.size(); ++i)
      for (std::size_t j = i + 1; j < boxes.size(); ++j)
        brute += boxes[i].min[0] <= boxes[j].max[0] && boxes[j].min[0] <= boxes[i].max[0];
    EXPECT_EQ(pairsOverlappingOnX(boxes), brute) << "scene " << scene;
  }
}

TEST(Benchmark, ASweepIsSkippedWhereTooManyPairsOverlapOnX) {
  // Ten boxes on one x interval (45 pairs) but apart on y: only the sweep's work is large.
  std::vector<Aabb> boxes;
  for (int i = 0; i < 10; ++i) boxes.push_back(Aabb{{0, float(3 * i), 0}, {1, float(3 * i + 1), 1}});
  const SceneStart start{boxes, -1, 40};
  EXPECT_FALSE(sweepSkipReason(45)(start).has_value());
  const auto reason = sweepSkipReason(44)(start);
  ASSERT_TRUE(reason.has_value());
  EXPECT_NE(reason->find("45 on this scene"), std::string::npos) << *reason;
  EXPECT_NE(reason->find("--max-sweep-tests"), std::string::npos) << *reason;
  // In the line-up, exactly the two sweeps that cannot be stopped midway carry the rule.
  LineUpConfig l;
  l.maxSweepTests = 44;
  std::set<std::string> skipped;
  for (const auto& s : standardLineUp(l))
    if (s.skipReason && s.skipReason(start)) skipped.insert(s.name);
  EXPECT_EQ(skipped, (std::set<std::string>{"FCL SaP (rebuilt)", "ODE dSweepAndPruneSpace"}));
}

TEST(Benchmark, MethodsRunInADifferentOrderEveryFrame) {
  LineUpConfig l;
  std::vector<int> log;
  constexpr int kMethods = 4;
  std::vector<MethodSpec> lineUp;
  for (int i = 0; i < kMethods; ++i) lineUp.push_back(fakePeer(i, 1e-3, false, &log));
  auto config = tinyConfig();
  config.objectCounts = {20};
  config.frames = 20;
  runQuietly(config, lineUp, l);
  ASSERT_EQ(log.size(), kMethods * (config.frames + config.warmup));
  std::set<int> firsts, predecessorsOfZero;
  for (std::size_t f = 0; f < log.size() / kMethods; ++f) {
    const std::vector<int> frame(log.begin() + static_cast<long>(f * kMethods), log.begin() + static_cast<long>((f + 1) * kMethods));
    EXPECT_EQ(std::set<int>(frame.begin(), frame.end()).size(), std::size_t{kMethods});  // each once a frame
    firsts.insert(frame[0]);
    const auto zero = std::find(frame.begin(), frame.end(), 0);
    if (zero != frame.begin()) predecessorsOfZero.insert(*(zero - 1));
  }
  EXPECT_GE(firsts.size(), 3u);
  EXPECT_GE(predecessorsOfZero.size(), 2u);  // not always after the same method
}

TEST(CompareSorted, CountsMissingAndExtraPairs) {
  const std::vector<Pair> exact = {{0, 1}, {0, 2}, {3, 4}};
  const std::vector<Pair> got = {{0, 1}, {1, 2}, {3, 4}, {5, 6}};
  const auto d = compareSorted(got, exact);
  EXPECT_EQ(d.missing, 1u);
  EXPECT_EQ(d.extra, 2u);
}

TEST(LinkModel, ALinkSlowerThanTheLoadPortAddsOnlyItsExcess) {
  LinkModel link{1e9, 2e-6};  // 1 GB/s: 24 kB of boxes take 24 us
  RunStats s;
  s.runs = 30;    // cells: they do not pay the latency ...
  s.batches = 3;  // ... hand-overs do
  s.boxesSent = 1000;
  s.loadCycles = 1000;  // 10 us at 100 MHz through the load port
  s.beatsReceived = 500;
  EXPECT_DOUBLE_EQ(transferSeconds(s, link, 100e6), 3 * 2e-6 + (24e-6 - 10e-6) + 2000.0 / 1e9);
}

TEST(LinkModel, ALinkFasterThanTheLoadPortAddsNothingForBoxes) {
  LinkModel link{100e9, 1e-6};  // 24 kB in 0.24 us, the port needs 10 us: the loads (device time) dominate
  RunStats s;
  s.runs = 1;
  s.batches = 1;
  s.boxesSent = 1000;
  s.loadCycles = 1000;
  s.beatsReceived = 0;
  EXPECT_DOUBLE_EQ(transferSeconds(s, link, 100e6), 1e-6);
}

TEST(AcceleratorMethod, DeviceTimeCountsLoadCycles) {
  auto d = std::make_shared<DeviceConfig>();
  d->makeBackend = [] { return std::make_unique<ModelBackend>(builtDeviceParams()); };
  d->clockHz = 100e6;
  AcceleratorMethod method(d, 16);
  const auto boxes = bpaccel::testing::adversarialScenes(200, 1)[0].second;
  method.update(boxes);
  const FrameTime t = method.frameTime(0.0);
  ASSERT_TRUE(t.parts.has_value());
  EXPECT_DOUBLE_EQ(t.parts->deviceSeconds,
                   static_cast<double>(t.parts->stats.loadCycles + t.parts->stats.cycles) / 100e6);
  EXPECT_GT(t.parts->stats.cycles, 0u);
}

TEST(AcceleratorMethod, BatchesPayTheLinkLatencyOncePerHandOverAndFindTheSamePairs) {
  const auto boxes = bpaccel::testing::adversarialScenes(1500, 4)[0].second;
  const auto frame = [&](std::size_t cellsPerBatch, std::vector<Pair>& pairs, std::size_t firstBatchCells = 0) {
    auto d = std::make_shared<DeviceConfig>();
    d->firstBatchCells = firstBatchCells;
    d->makeBackend = [] { return std::make_unique<ModelBackend>(builtDeviceParams()); };
    d->clockHz = 100e6;
    d->link.bandwidthBytesPerSecond = 1e12;  // the load port is slower: boxes add no link time
    d->link.latencySeconds = 1e-6;
    d->cellsPerBatch = cellsPerBatch;
    AcceleratorMethod method(d, 16);
    method.update(boxes);
    method.pairs(pairs);
    return *method.frameTime(0.0).parts;
  };
  std::vector<Pair> single, batched;
  const ModelledParts one = frame(1, single), eight = frame(8, batched);
  EXPECT_EQ(bpaccel::testing::sorted(batched), bpaccel::testing::sorted(single));
  EXPECT_EQ(one.stats.batches, one.stats.runs);
  ASSERT_GT(one.stats.runs, 16u);
  EXPECT_EQ(eight.stats.runs, one.stats.runs);
  EXPECT_EQ(eight.stats.batches, (one.stats.runs + 7) / 8);
  EXPECT_EQ(eight.stats.issueCycles, one.stats.issueCycles);
  EXPECT_NEAR(one.transferSeconds - eight.transferSeconds,
              static_cast<double>(one.stats.batches - eight.stats.batches) * 1e-6, 1e-12);

  // Slow start: hand-overs of 2, 4, then 8 cells.
  std::vector<Pair> slowStarted;
  const ModelledParts slow = frame(8, slowStarted, 2);
  EXPECT_EQ(bpaccel::testing::sorted(slowStarted), bpaccel::testing::sorted(single));
  EXPECT_EQ(slow.stats.runs, one.stats.runs);
  EXPECT_EQ(slow.stats.issueCycles, one.stats.issueCycles);
  EXPECT_EQ(slow.stats.batches, 2 + (one.stats.runs - 6 + 7) / 8);
  EXPECT_NEAR(slow.transferSeconds - eight.transferSeconds,
              static_cast<double>(slow.stats.batches - eight.stats.batches) * 1e-6, 1e-12);
}

TEST(DeviceClock, TheDefaultClockIsTheFmaxOfAReportOfTheSameMAndArchitectureOnly) {
  const auto dir = std::filesystem::temp_directory_path() / ("bpaccel-clock-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const nlohmann::json& j) {
    const auto path = (dir / name).string();
    std::ofstream(path) << j.dump();
    return path;
  };
  const nlohmann::json seed8 = {
      {"status", "ok"}, {"result_valid", true}, {"m", 8}, {"arch", "seed"}, {"ecp5", {{"fmax_mhz", 107.5}}}};
  const auto ok = clockFromFpgaReport(write("seed8.json", seed8), 8, "seed");
  EXPECT_DOUBLE_EQ(ok.hz, 107.5e6);
  EXPECT_NE(ok.source.find("measured by nextpnr"), std::string::npos) << ok.source;
  EXPECT_EQ(ok.source.find("revision"), std::string::npos) << ok.source;  // the report names none

  // A report that names its design and placement: the clock's label says them.
  auto named = seed8;
  named["source_revision"] = "0b709b6";
  named["nextpnr_seed"] = 3;
  const auto labelled = clockFromFpgaReport(write("named.json", named), 8, "seed");
  EXPECT_NE(labelled.source.find("revision 0b709b6, placer seed 3"), std::string::npos) << labelled.source;
  named["source_revision"] = nullptr;  // the flow ran outside a git checkout
  EXPECT_DOUBLE_EQ(clockFromFpgaReport(write("named.json", named), 8, "seed").hz, 107.5e6);

  // The other architecture's report at the same m must not set the clock.
  const auto otherArch = clockFromFpgaReport(write("seed8.json", seed8), 8, "stream");
  EXPECT_DOUBLE_EQ(otherArch.hz, 100e6);
  EXPECT_NE(otherArch.source.find("arch = seed, not stream"), std::string::npos) << otherArch.source;

  auto noArch = seed8;
  noArch.erase("arch");  // reports older than the stream architecture are the seed's
  EXPECT_DOUBLE_EQ(clockFromFpgaReport(write("old.json", noArch), 8, "seed").hz, 107.5e6);
  EXPECT_DOUBLE_EQ(clockFromFpgaReport(write("old.json", noArch), 8, "stream").hz, 100e6);

  const auto otherM = clockFromFpgaReport(write("seed8.json", seed8), 16, "seed");
  EXPECT_DOUBLE_EQ(otherM.hz, 100e6);
  EXPECT_NE(otherM.source.find("m = 8, not 16"), std::string::npos) << otherM.source;

  // Nor a report of other key widths: a 16-bit device's Fmax is not the 32-bit one's.
  auto narrow = seed8;
  narrow["key_width"] = 16;
  EXPECT_DOUBLE_EQ(clockFromFpgaReport(write("narrow.json", narrow), 8, "seed", 16).hz, 107.5e6);
  const auto otherKeys = clockFromFpgaReport(write("narrow.json", narrow), 8, "seed");
  EXPECT_DOUBLE_EQ(otherKeys.hz, 100e6);
  EXPECT_NE(otherKeys.source.find("16-bit keys, not 32"), std::string::npos) << otherKeys.source;
  EXPECT_EQ(fpgaReportPath(8, "seed", 32), "results/fpga/m8.json");
  EXPECT_EQ(fpgaReportPath(64, "stream", 16), "results/fpga/stream-m64-k16.json");

  auto notFit = seed8;
  notFit["status"] = "does_not_fit";
  EXPECT_DOUBLE_EQ(clockFromFpgaReport(write("nofit.json", notFit), 8, "seed").hz, 100e6);
  std::ofstream(dir / "broken.json") << "{ not json";
  const auto broken = clockFromFpgaReport((dir / "broken.json").string(), 8, "seed");
  EXPECT_DOUBLE_EQ(broken.hz, 100e6);
  EXPECT_NE(broken.source.find("unreadable"), std::string::npos) << broken.source;
  EXPECT_NE(clockFromFpgaReport((dir / "missing.json").string(), 8, "seed").source.find("no FPGA report"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

namespace {

// Runs the real bpaccel binary (in folder `cwd` if one is given); returns its exit code and standard output.
std::pair<int, std::string> runBenchCli(const std::string& args, const std::string& subcommand = "run",
                                        const std::filesystem::path& cwd = {}) {
  const std::string cd = cwd.empty() ? "" : "cd '" + cwd.string() + "' && ";
  const std::string cmd = cd + std::string(BPACCEL_BENCH_CLI) + " " + subcommand + " " + args + " 2>/dev/null";
  std::string out;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  std::size_t got;
  while ((got = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), got);
  return {WEXITSTATUS(::pclose(pipe)), out};
}

}  // namespace

TEST(BenchCli, NamesTheLinkUnitAndListsSkippedMethodsInTableAndJson) {
  const auto [helpCode, help] = runBenchCli("--help");
  EXPECT_EQ(helpCode, 0);
  EXPECT_NE(help.find("--link-gbytes-per-s"), std::string::npos);
  EXPECT_NE(help.find("gigabytes per second"), std::string::npos);

  const auto json = std::filesystem::temp_directory_path() / ("bpaccel-bench-" + std::to_string(::getpid()) + ".json");
  const auto [code, table] = runBenchCli("--objects 40 --frames 1 --warmup 0 --backend model --cell-sizes none 8 "
                                         "--max-all-pairs-tests 100 --many-worlds 8 --world-sizes 10 --world-frames 1 "
                                         "--whole-step-objects 100 --whole-step-rays 10 --query-objects 100 --query-count 10 "
                                         "--json " + json.string());
  EXPECT_EQ(code, 0) << table;
  EXPECT_NE(table.find("n=40 btSimpleBroadphase: skipped: tests all pairs"), std::string::npos) << table;
  EXPECT_NE(table.find("n=40 cpu k-d none: skipped"), std::string::npos) << table;
  EXPECT_NE(table.find("Many worlds: 8 worlds of n boxes"), std::string::npos) << table;
  std::ifstream in(json);
  const auto j = nlohmann::json::parse(in);
  std::size_t skipped = 0;
  for (const auto& m : j["rows"][0]["methods"]) skipped += m.contains("skipped");
  EXPECT_EQ(skipped, 4u);  // btSimpleBroadphase, the accelerator on each profile and cpu without the tree
  // Every accelerator row names its profile, by default both built-in ones, in its name and its JSON.
  std::set<std::string> profiles;
  for (const auto& m : j["rows"][0]["methods"])
    if (m["kind"] == "accelerator") {
      const std::string profile = m["profile"]["name"];
      EXPECT_NE(m["name"].get<std::string>().find(" on " + profile), std::string::npos) << m["name"];
      profiles.insert(profile);
    }
  EXPECT_EQ(profiles, (std::set<std::string>{"ecp5-5g", "gen3x8"}));
  EXPECT_EQ(j["configuration"]["profiles"].size(), 2u);
  std::filesystem::remove(json);
}

TEST(BenchCli, WritesNoResultsFileUnlessToldWhere) {
  // A trial run must not overwrite the committed results/bench.json of the folder it runs in.
  const auto dir = std::filesystem::temp_directory_path() / ("bpaccel-nojson-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto [code, table] = runBenchCli("--objects 40 --frames 1 --warmup 0 --no-accelerator --cell-sizes 8 "
                                         "--many-worlds 0 --whole-step-objects 0 --query-objects none", "run", dir);
  EXPECT_EQ(code, 0) << table;
  EXPECT_NE(table.find("All frames validated. Results: not written (no --json)"), std::string::npos) << table;
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  std::filesystem::remove_all(dir);
}

TEST(BenchCli, QueryObjectsNoneRunsNoQueryTableAndRefusesWhatIsNotACount) {
  const auto json = std::filesystem::temp_directory_path() / ("bpaccel-noqueries-" + std::to_string(::getpid()) + ".json");
  const std::string rest = "--objects 40 --frames 1 --warmup 0 --no-accelerator --cell-sizes 8 --many-worlds 0 "
                           "--whole-step-objects 0 --json " + json.string();
  const auto [code, table] = runBenchCli("--query-objects none " + rest);
  EXPECT_EQ(code, 0) << table;
  std::ifstream in(json);
  const auto j = nlohmann::json::parse(in);
  EXPECT_FALSE(j.contains("queries"));
  EXPECT_EQ(j["rows"].size(), 1u);
  std::filesystem::remove(json);
  for (const char* bad : {"0", "lots", "-5", "5.5", "1e5"})
    EXPECT_NE(runBenchCli(std::string("--query-objects ") + bad + " " + rest).first, 0) << bad;
}

TEST(BenchCli, TheManyWorldsTableRunsInTheBenchAndAlone) {
  const auto json = std::filesystem::temp_directory_path() / ("bpaccel-worlds-" + std::to_string(::getpid()) + ".json");
  const auto [code, table] = runBenchCli("--worlds 8 --world-sizes 10 20 --world-frames 1 --world-warmup 0 --backend model "
                                         "--json " + json.string(), "worlds");
  EXPECT_EQ(code, 0) << table;
  for (const char* s : {"Many worlds: 8 worlds", "n=20", "accelerator ManyWorlds on ecp5-5g", "Every world of every frame validated"})
    EXPECT_NE(table.find(s), std::string::npos) << s << "\n" << table;
  std::ifstream in(json);
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["rows"].size(), 2u);
  std::filesystem::remove(json);
}

TEST(Benchmark, AMethodSlowerThanTheLimitIsStoppedAndListedWithItsTime) {
  LineUpConfig l;
  MethodSpec slow = fakePeer(0, 1e-3, false);
  slow.name = "slow";
  slow.make = [](const SceneStart&) {
    struct Slow final : TimedMethod {
      void update(std::span<const Aabb> boxes) override {
        sortAndSweepPairs(boxes, pairs_);
        const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(30);
        while (std::chrono::steady_clock::now() < until) {
        }
      }
      void pairs(std::vector<Pair>& out) override { out = pairs_; }
      std::vector<Pair> pairs_;
    };
    return std::make_unique<Slow>();
  };
  auto config = tinyConfig();
  config.maxMethodSeconds = 0.01;
  const auto j = runQuietly(config, {fakePeer(1, 1e-3, false), slow}, l);
  for (const auto& row : j["rows"]) {
    EXPECT_FALSE(row["methods"][0].contains("skipped"));
    ASSERT_TRUE(row["methods"][1].contains("skipped"));
    EXPECT_NE(row["methods"][1]["skipped"].get<std::string>().find("stopped at frame 1"), std::string::npos);
    EXPECT_TRUE(row["methods"][1]["frame_ms"].is_null());
  }
}

namespace {

// The cpu rows of the first row whose name contains `part`, each checked exact; their names.
std::vector<std::string> exactCpuRowsNamed(std::size_t cpuThreads, const std::string& part) {
  auto l = tinyLineUp();
  l.cpuThreads = cpuThreads;
  const auto j = runQuietly(tinyConfig(), standardLineUp(l), l);
  std::vector<std::string> names;
  for (const auto& m : j["rows"][0]["methods"])
    if (m["name"].get<std::string>().find(part) != std::string::npos) {
      names.push_back(m["name"]);
      EXPECT_EQ(m["kind"], "cpu") << names.back();
      EXPECT_EQ(m["missing_pairs"], 0) << names.back();
      EXPECT_EQ(m["extra_pairs"], 0) << names.back();
      if (!names.back().ends_with(" threads")) continue;
      // Its speedup over the same row on one thread, and that per thread.
      const std::string one = names.back().substr(0, names.back().rfind(", "));
      for (const auto& o : j["rows"][0]["methods"])
        if (o["name"] == one) {
          const double speedup = o["frame_ms"]["median"].get<double>() / m["frame_ms"]["median"].get<double>();
          EXPECT_DOUBLE_EQ(m["speedup_over_one_thread"].get<double>(), speedup) << names.back();
          EXPECT_DOUBLE_EQ(m["parallel_efficiency"].get<double>(), speedup / cpuThreads) << names.back();
        }
      EXPECT_TRUE(m.contains("parallel_efficiency")) << names.back();
    }
  return names;
}

}  // namespace

TEST(Benchmark, TheCpuBackendAlsoRunsOnSeveralThreadsExactly) {
  // Cell sizes 4 and 16 (none has one cell to share), and the automatic choice.
  EXPECT_EQ(exactCpuRowsNamed(2, ", 2 threads"),
            (std::vector<std::string>{"cpu k-d 4, 2 threads", "cpu k-d 16, 2 threads", "cpu auto, 2 threads"}));
}

TEST(Benchmark, TheCpuBackendsAutomaticChoiceRunsExactlyBesideTheFixedOnes) {
  EXPECT_EQ(exactCpuRowsNamed(1, "cpu auto"), std::vector<std::string>{"cpu auto"});
  auto l = tinyLineUp();
  l.cpuThreads = 1;
  const auto json = runQuietly(tinyConfig(), standardLineUp(l), l);  // a range-for over its subscript would outlive it
  for (const auto& m : json["rows"][0]["methods"])
    if (m["name"] == "cpu auto") {
      EXPECT_EQ(m["cell_size"], "auto");
      EXPECT_EQ(m["partition"], "auto");
    }
}

namespace {

// btDbvtBroadphase whose ray tests lose the first proxy each ray meets.
class RayDroppingDbvt final : public btDbvtBroadphase {
 public:
  void rayTest(const btVector3& from, const btVector3& to, btBroadphaseRayCallback& callback, const btVector3& lo,
               const btVector3& hi) override {
    struct SkipFirst final : btBroadphaseRayCallback {
      explicit SkipFirst(btBroadphaseRayCallback& inner) : inner(inner) {
        m_rayDirectionInverse = inner.m_rayDirectionInverse;
        for (int a = 0; a < 3; ++a) m_signs[a] = inner.m_signs[a];
        m_lambda_max = inner.m_lambda_max;
      }
      bool process(const btBroadphaseProxy* proxy) override { return std::exchange(first, false) || inner.process(proxy); }
      btBroadphaseRayCallback& inner;
      bool first = true;
    } skip(callback);
    btDbvtBroadphase::rayTest(from, to, skip, lo, hi);
  }
};

}  // namespace

TEST(WholeStep, TheRaysAfterEachStepAreTimedAndEveryAnswerChecked) {
  auto config = tinyConfig();
  config.objectCounts = {30};
  config.frames = 1;
  config.wholeStepObjects = 60;
  config.wholeStepFrames = 3;
  config.wholeStepRays = 40;
  LineUpConfig l;
  const auto j = runQuietly(config, {fakePeer(0, 1e-3, false)}, l);
  const auto& w = j["whole_step"];
  EXPECT_EQ(w["rays_per_frame"], 40);
  ASSERT_EQ(w["methods"].size(), 2u);
  for (const auto& m : w["methods"]) {
    EXPECT_GT(m["ray_proxies"]["reported"].get<std::uint64_t>(), 0u) << m["name"];
    EXPECT_EQ(m["ray_proxies"]["missing"], 0) << m["name"];
    EXPECT_GE(m["step_and_rays_ms"]["median"].get<double>(), m["step_ms"]["min"].get<double>()) << m["name"];
  }
  EXPECT_EQ(w["methods"][1]["ray_proxies"]["extra"], 0);  // the drop-in's rays: exactly Bullet's test
  EXPECT_NE(Benchmark::table(j).find("step + rays"), std::string::npos);
  // A broad phase whose rays lose a proxy is caught by the same check.
  SceneConfig scene;
  scene.objects = 60;
  const auto lossy = timeWholeSteps(scene, [] { return std::make_unique<RayDroppingDbvt>(); },
                                    {.frames = 2, .warmup = 1, .rays = 40});
  EXPECT_GT(lossy.rayMissing, 0u);
}
