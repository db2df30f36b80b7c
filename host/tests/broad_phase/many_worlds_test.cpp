// ManyWorlds: every world's pairs equal brute force on that world alone, on
// the cpu backend, on modelled devices (small capacity, narrow keys) and on
// the Verilated device, for many world counts and sizes; worlds are batched as cells; a bad box names
// its world; a backend that loses pairs is caught.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "broad_phase/many_worlds.hpp"
#include "device/cpu_backend.hpp"
#include "device/model_backend.hpp"
#include "device/rtl/rtl_backend.hpp"
#include "dropping_backend.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

// W worlds of 0 to maxSize boxes on a coarse integer lattice, so that many
// boxes touch exactly; world sizes 0, 1, 2 and maxSize always appear.
std::vector<std::vector<Aabb>> randomWorlds(std::size_t w, std::size_t maxSize, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::vector<Aabb>> worlds(w);
  for (std::size_t k = 0; k < w; ++k) {
    const std::size_t n = k < 4 ? std::min<std::size_t>(k == 3 ? maxSize : k, maxSize)
                                : std::uniform_int_distribution<std::size_t>(0, maxSize)(rng);
    worlds[k] = scatteredBoxes(n, seed * 7919u + static_cast<unsigned>(k), 0, 12, 0, 5);
    for (Aabb& b : worlds[k])
      for (int a = 0; a < 3; ++a) b.min[a] = std::round(b.min[a]), b.max[a] = std::round(b.max[a]);
  }
  return worlds;
}

std::vector<std::span<const Aabb>> spans(const std::vector<std::vector<Aabb>>& worlds) {
  return {worlds.begin(), worlds.end()};
}

// The first world whose pairs differ from brute force, or -1.
long firstWrongWorld(Backend& backend, const std::vector<std::vector<Aabb>>& worlds) {
  ManyWorlds many(backend);
  WorldPairs out;
  many.findPairs(spans(worlds), out);
  if (out.worlds() != worlds.size()) return 0;
  for (std::size_t w = 0; w < worlds.size(); ++w) {
    const auto got = out.of(w);
    if (std::vector<Pair>(got.begin(), got.end()) != bruteForce(worlds[w])) return static_cast<long>(w);
  }
  return -1;
}

DeviceParams smallDevice(unsigned keyWidth) {
  DeviceParams p = DeviceParams::stream(4, 32, 5, 4, true);
  p.keyWidth = keyWidth;
  return p;
}

TEST(ManyWorlds, EveryWorldsPairsAreBruteForceOnEveryBackend) {
  CpuBackend cpu;
  ModelBackend model(smallDevice(32)), narrow(smallDevice(9));
  for (Backend* backend : std::initializer_list<Backend*>{&cpu, &model, &narrow})
    for (const std::size_t w : {0u, 1u, 5u, 150u})
      for (const std::size_t maxSize : {2u, 16u, 40u}) {  // 40: beyond the devices' capacity of 32
        const auto worlds = randomWorlds(w, maxSize, static_cast<unsigned>(w * 100 + maxSize));
        EXPECT_EQ(firstWrongWorld(*backend, worlds), -1)
            << backend->name() << " key width " << backend->keyWidth() << ", " << w << " worlds of up to " << maxSize;
      }
}

TEST(ManyWorlds, BatchesTheWorldsAsCellsOfOneHandOver) {
  ModelBackend model(smallDevice(32));
  const auto worlds = randomWorlds(200, 30, 3);
  std::size_t withPairsToTest = 0;
  for (const auto& world : worlds) withPairsToTest += world.size() >= 2;
  ManyWorlds many(model);
  WorldPairs out;
  many.findPairs(spans(worlds), out);
  EXPECT_EQ(many.stats().runs, withPairsToTest);
  EXPECT_LT(many.stats().batches, many.stats().runs);
  EXPECT_GT(out.pairs().size(), 200u);
}

// The Verilated hardware: each world one cell of its batches.
TEST(ManyWorlds, EveryWorldsPairsAreBruteForceOnTheVerilatedDevice) {
  RtlBackend rtl;
  const auto worlds = randomWorlds(40, 24, 6);
  EXPECT_EQ(firstWrongWorld(rtl, worlds), -1);
}

TEST(ManyWorlds, NamesTheWorldAndBoxOfABadBox) {
  CpuBackend cpu;
  auto worlds = randomWorlds(6, 10, 4);
  worlds[4].at(5).min[1] = std::numeric_limits<float>::quiet_NaN();
  ManyWorlds many(cpu);
  WorldPairs out;
  try {
    many.findPairs(spans(worlds), out);
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("world 4: object 5"), std::string::npos) << what;
  }
  EXPECT_EQ(out.worlds(), 0u);
}

TEST(ManyWorlds, CatchesABackendThatLosesPairs) {
  DroppingBackend losing;
  EXPECT_NE(firstWrongWorld(losing, randomWorlds(20, 16, 5)), -1);
}

}  // namespace
