#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "broad_phase/broad_phase.hpp"
#include "device/cpu_backend.hpp"
#include "scenes/exact_pairs.hpp"
#include "scenes/scene_families.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

std::vector<SceneFamily> kinematicFamilies() {
  std::vector<SceneFamily> f = allSceneFamilies();
  f.erase(std::remove(f.begin(), f.end(), SceneFamily::Cube), f.end());
  return f;
}

std::vector<std::vector<Aabb>> frames(SceneFamily family, std::size_t objects, std::uint32_t seed, std::size_t count) {
  SceneConfig config;
  config.objects = objects;
  config.seed = seed;
  const auto source = makeFrameSource(family, config);
  std::vector<std::vector<Aabb>> out(count);
  for (auto& f : out) {
    source->aabbs(f);
    source->step();
  }
  return out;
}

bool sameBits(const std::vector<Aabb>& a, const std::vector<Aabb>& b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](const Aabb& x, const Aabb& y) { return x.min == y.min && x.max == y.max; });
}

}  // namespace

TEST(SceneFamilies, EveryFamilyIsReproducibleFromItsSeedAndDiffersWithAnother) {
  for (SceneFamily f : kinematicFamilies()) {
    const auto a = frames(f, 500, 7, 5), b = frames(f, 500, 7, 5), c = frames(f, 500, 8, 5);
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_TRUE(sameBits(a[k], b[k])) << familyName(f) << " frame " << k;
      EXPECT_FALSE(sameBits(a[k], c[k])) << familyName(f) << " frame " << k;
    }
    EXPECT_FALSE(sameBits(a[0], a[4])) << familyName(f) << ": the boxes move";
  }
}

TEST(SceneFamilies, EveryBoxOfEveryFrameStaysInsideTheWorldAndIsWellFormed) {
  for (SceneFamily f : kinematicFamilies()) {
    SceneConfig config;
    config.objects = 800;
    const auto source = makeFrameSource(f, config);
    const auto lo = source->worldLo(), hi = source->worldHi();
    std::vector<Aabb> boxes;
    for (int frame = 0; frame < 120; ++frame, source->step()) {
      source->aabbs(boxes);
      ASSERT_EQ(boxes.size(), 800u);
      for (const Aabb& b : boxes)
        for (int a = 0; a < 3; ++a) {
          ASSERT_LE(lo[a], b.min[a]) << familyName(f) << " frame " << frame;
          ASSERT_LE(b.min[a], b.max[a]) << familyName(f) << " frame " << frame;
          ASSERT_LE(b.max[a], hi[a]) << familyName(f) << " frame " << frame;
        }
    }
  }
}

TEST(SceneFamilies, EachFamilyHasTheShapeItsNameSays) {
  const auto extent = [](const Aabb& b, int a) { return b.max[a] - b.min[a]; };
  const auto first = [](SceneFamily f) { return frames(f, 4000, 1, 1).front(); };
  {  // sizes: extents spread over more than 50 times, points among them
    const auto boxes = first(SceneFamily::Sizes);
    float smallest = INFINITY, largest = 0;
    std::size_t points = 0;
    for (const Aabb& b : boxes) {
      const float e = std::max({extent(b, 0), extent(b, 1), extent(b, 2)});
      points += e == 0;
      if (e > 0) smallest = std::min(smallest, e);
      largest = std::max(largest, e);
    }
    EXPECT_GT(largest / smallest, 50);
    EXPECT_GT(points, 40u);
  }
  {  // layer: every box centred at one height
    const auto boxes = first(SceneFamily::Layer);
    for (const Aabb& b : boxes) EXPECT_NEAR((b.min[1] + b.max[1]) / 2, (boxes[0].min[1] + boxes[0].max[1]) / 2, 1e-3);
  }
  {  // poles: each at least five times longer than thick (4 long, 0.4 thick, turned by 45 degrees: 7)
    const auto poles = first(SceneFamily::Poles);
    for (const Aabb& b : poles) {
      const float e[3] = {extent(b, 0), extent(b, 1), extent(b, 2)};
      EXPECT_GT(*std::max_element(e, e + 3), 5 * *std::min_element(e, e + 3));
    }
  }
  {  // flat: the world is at least ten times wider than high
    SceneConfig config;
    config.objects = 4000;
    const auto source = makeFrameSource(SceneFamily::Flat, config);
    EXPECT_GT(source->worldHi()[0] - source->worldLo()[0], 10 * (source->worldHi()[1] - source->worldLo()[1]));
  }
  {  // clusters: half the boxes lie in a small share of the world's volume
    const auto boxes = first(SceneFamily::Clusters);
    std::vector<std::size_t> counts(20 * 20 * 20, 0);
    float e = 0;
    for (const Aabb& b : boxes) e = std::max(e, b.max[0]);
    for (const Aabb& b : boxes) {
      std::size_t c = 0;
      for (int a = 0; a < 3; ++a) c = c * 20 + std::min<std::size_t>(19, static_cast<std::size_t>(b.min[a] / e * 20));
      ++counts[c];
    }
    std::sort(counts.rbegin(), counts.rend());
    std::size_t held = 0, cells = 0;
    while (held < boxes.size() / 2) held += counts[cells++];
    EXPECT_LT(cells, counts.size() / 50) << "half the boxes in " << cells << " of 8000 cells";
  }
}

TEST(SceneFamilies, RejectsAnUnknownNameListingTheFamilies) {
  try {
    parseSceneFamily("cubes");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cube, sizes, clusters, flat, poles, layer"), std::string::npos) << e.what();
  }
  for (SceneFamily f : allSceneFamilies()) EXPECT_EQ(parseSceneFamily(std::string(familyName(f))), f);
}

TEST(ExactPairs, MatchesBruteForceOnEveryFamily) {
  for (SceneFamily f : allSceneFamilies())
    for (const auto& boxes : frames(f, 1500, 3, 2)) {
      std::vector<Pair> pairs;
      exactPairs(boxes, pairs);
      EXPECT_EQ(pairs, bruteForce(boxes)) << familyName(f);
    }
}

TEST(CpuBackend, TheAutomaticChoiceIsExactOnEveryFamilyOnOneAndTwoThreads) {
  for (SceneFamily f : allSceneFamilies())
    for (std::size_t threads : {1, 2}) {
      BroadPhase bp([] { return std::make_unique<CpuBackend>(); }, {.threads = threads});
      for (std::size_t n : {50, 3000})
        for (const auto& boxes : frames(f, n, 4, 3)) {
          std::vector<Pair> pairs, exact;
          bp.findPairs(boxes, pairs);
          exactPairs(boxes, exact);
          EXPECT_EQ(sorted(pairs), exact) << familyName(f) << " n=" << n << " threads " << threads << " choice "
                                          << choiceName(bp.choice());
        }
    }
}

TEST(CpuBackend, TheAutomaticCellSizeSettlesWithItsMeanCellInTheBandOnEveryFamily) {
  std::size_t smallest = AutomaticChoice::kLargestCellSize, largest = 0;
  for (SceneFamily f : allSceneFamilies()) {
    BroadPhase bp([] { return std::make_unique<CpuBackend>(); }, {});
    std::vector<Pair> pairs;
    const auto scene = frames(f, 8000, 5, 6);
    for (const auto& boxes : scene) bp.findPairs(boxes, pairs);
    const std::size_t size = *bp.choice().cellSize;
    const double mean = occupancyOf(bp.partition(), scene.back().size()).meanCell();
    const bool inBand = mean >= AutomaticChoice::kMeanCellLow && mean <= AutomaticChoice::kMeanCellHigh;
    const bool atALimit = (size == AutomaticChoice::kSmallestCellSize && mean > AutomaticChoice::kMeanCellHigh) ||
                          (size == AutomaticChoice::kLargestCellSize && mean < AutomaticChoice::kMeanCellLow);
    EXPECT_TRUE(inBand || atALimit) << familyName(f) << ": cell size " << size << ", mean cell " << mean;
    smallest = std::min(smallest, size);
    largest = std::max(largest, size);
  }
  // The families' densities differ enough that one size cannot suit them all.
  EXPECT_LT(smallest, largest);
}
