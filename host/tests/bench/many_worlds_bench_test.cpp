#include <gtest/gtest.h>

#include <set>

#include "benchmark.hpp"
#include "rtl_device.hpp"
#include "bpaccel_params.h"
#include "device/rtl/rtl_backend.hpp"
#include "many_worlds_bench.hpp"

using namespace bpaccel;

namespace {

ManyWorldsBenchConfig tinyWorlds() {
  ManyWorldsBenchConfig c;
  c.worlds = 6;
  c.boxesPerWorld = {8, 12};
  c.frames = 2;
  c.warmup = 1;
  c.scene.density = 0.15f;  // crowded small cubes: every world has pairs to miss
  return c;
}

// A method whose pairs of world `world` lose their last pair.
class DropsOnePair final : public WorldsMethod {
 public:
  DropsOnePair(std::unique_ptr<WorldsMethod> inner, std::size_t world) : inner_(std::move(inner)), world_(world) {}
  void update(std::span<const std::span<const Aabb>> worlds) override { inner_->update(worlds); }
  void pairs(std::size_t w, std::vector<Pair>& out) override {
    inner_->pairs(w, out);
    if (w == world_ && !out.empty()) out.pop_back();
  }

 private:
  std::unique_ptr<WorldsMethod> inner_;
  std::size_t world_;
};

}  // namespace

TEST(BouncingWorlds, KeepsEveryBoxMovingInsideItsWorldsCube) {
  SceneConfig cube;
  BouncingWorlds worlds(3, 20, cube);
  std::vector<Aabb> before(worlds.world(1).begin(), worlds.world(1).end());
  for (int f = 0; f < 200; ++f) {
    worlds.step();
    for (std::size_t w = 0; w < worlds.worlds(); ++w)
      for (const Aabb& b : worlds.world(w))
        for (int a = 0; a < 3; ++a) {
          ASSERT_GE(b.min[a], 0.0f);
          ASSERT_LE(b.max[a], worlds.edge());
          ASSERT_LE(b.min[a], b.max[a]);
        }
  }
  std::size_t moved = 0;
  for (std::size_t i = 0; i < before.size(); ++i) moved += before[i].min[0] != worlds.world(1)[i].min[0];
  EXPECT_EQ(moved, before.size());
}

TEST(ManyWorldsBench, EveryMethodFindsEveryWorldsPairsAndTheAcceleratorIsModelledPerProfile) {
  auto config = tinyWorlds();
  config.device = rtlDevice();
  const ProfileInputs in{.device = {BPACCEL_M, "stream", 32}, .fpgaDir = "/nonexistent", .lfe5uReport = ""};
  config.profiles = {ecp5FiveGProfile(in), gen3x8Profile(in)};
  const auto j = runManyWorldsBench(config, manyWorldsLineUp(config.device), [](const std::string&) {});
  ASSERT_EQ(j["rows"].size(), 2u);
  for (const auto& row : j["rows"]) {
    EXPECT_GT(row["exact_pairs_per_frame_mean"].get<double>(), 0);
    std::set<std::string> names;
    for (const auto& m : row["methods"]) {
      names.insert(m["name"]);
      ASSERT_FALSE(m.contains("skipped")) << m["name"];
      EXPECT_EQ(m["missing_pairs"], 0) << m["name"];
      EXPECT_GT(m["frame_ms"]["median"].get<double>(), 0) << m["name"];
      if (m["kind"] == "accelerator") {
        EXPECT_TRUE(m.contains("profile")) << m["name"];
        EXPECT_GT(m["device_ms_modelled"]["median"].get<double>(), 0);
        EXPECT_NE(m["modelled"].get<std::string>().find("on profile"), std::string::npos);
      }
    }
    EXPECT_EQ(names, (std::set<std::string>{"cpu ManyWorlds", "btDbvtBroadphase, one per world",
                                            "FCL DynamicAABBTree, one per world",
                                            "FCL DynamicAABBTree, update(objects), one per world",
                                            "FCL DynamicAABBTree, rebuilt, one per world",
                                            "accelerator ManyWorlds on ecp5-5g", "accelerator ManyWorlds on gen3x8"}));
  }
  const std::string table = manyWorldsTable(j);
  for (const char* s : {"Many worlds: 6 worlds", "MODELLED", "accelerator ManyWorlds on gen3x8", "n=12"})
    EXPECT_NE(table.find(s), std::string::npos) << s << "\n" << table;
}

TEST(ManyWorldsBench, AMethodThatMissesAPairOfOneWorldFailsTheRunNamingTheWorld) {
  for (std::size_t kind : {0u, 1u}) {  // the cpu backend, then the accelerator
    auto lineUp = manyWorldsLineUp(rtlDevice());
    WorldsMethodSpec spec = kind == 0 ? lineUp.front() : lineUp.back();
    const auto make = spec.make;
    spec.make = [make](std::span<const std::span<const Aabb>> first, float edge) {
      return std::make_unique<DropsOnePair>(make(first, edge), 4);
    };
    auto config = tinyWorlds();
    config.device = rtlDevice();
    try {
      runManyWorldsBench(config, {spec}, [](const std::string&) {});
      FAIL() << "no ValidationFailure for " << spec.name;
    } catch (const ValidationFailure& e) {
      EXPECT_EQ(e.method(), spec.name + " (world 4)");
      EXPECT_EQ(e.difference().missing, 1u);
    }
  }
}
