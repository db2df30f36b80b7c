// The host's frame path to the binning device (on its C++ model): exact
// against brute force on float scenes, regions with their boundary pairs, the
// host's path for long boxes, bad input.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "broad_phase/binning_frame.hpp"
#include "broad_phase/broad_phase.hpp"
#include "device/binning/binning_model.hpp"
#include "scenes.hpp"

namespace bpaccel {
namespace {

using testing::bruteForce;
using testing::sorted;

/// A small device, so that scenes of a few hundred boxes need several regions.
BinningParams smallDevice() {
  BinningParams p;
  p.groupBits = {1, 1, 1}, p.lanesPerGroup = 2, p.keyWidth = 9, p.cellBits = 3;
  p.boxCapacity = 128, p.groupCapacity = 40, p.intakeBoxes = 2, p.pairsPerBeat = 4;
  p.memoryReadLatency = 2, p.itemQueueDepth = 6;
  return p;
}

std::vector<Pair> framePairs(FrameDevice& device, const std::vector<Aabb>& boxes, BinningFrameStats* stats = nullptr) {
  BinningFrame frame(device);
  std::vector<Pair> out;
  frame.findPairs(boxes, out);
  if (stats) *stats = frame.stats();
  return sorted(out);
}

TEST(BinningFrame, FindsExactlyTheFloatPairsOnAdversarialScenes) {
  BinningModel built(builtBinningParams()), small(smallDevice());
  for (std::size_t n : {0, 1, 2, 150, 700})
    for (const auto& [name, boxes] : testing::adversarialScenes(n, 17 + static_cast<unsigned>(n))) {
      SCOPED_TRACE(name + ", n = " + std::to_string(n));
      EXPECT_EQ(framePairs(built, boxes), bruteForce(boxes));
      EXPECT_EQ(framePairs(small, boxes), bruteForce(boxes));
    }
}

TEST(BinningFrame, CutsScenesAboveTheCapacityIntoRegionsOnTwoAxesAndKeepsEachBoundaryPairOnce) {
  BinningModel small(smallDevice());
  for (unsigned seed = 0; seed < 6; ++seed) {
    const auto boxes = testing::scatteredBoxes(400 + 100 * seed, seed, 0, 40, 0.1f, 3.0f);
    BinningFrame frame(small);
    std::vector<Pair> out;
    frame.findPairs(boxes, out);
    EXPECT_EQ(sorted(out), bruteForce(boxes)) << "seed " << seed;
    const BinningFrameStats& stats = frame.stats();
    EXPECT_GE(stats.frames, 4u);
    EXPECT_GT(stats.boundaryDrops, 0u) << "no pair was found by two regions: the boundary rule went untested";
    EXPECT_GT(stats.boxesSent, boxes.size()) << "no box straddled a region boundary";
    // A grid of regions over two axes (and cut again on refusal): no region is a slab across the whole scene.
    for (const PlannedFrame& f : frame.frames()) {
      int bounded = 0;
      for (int a = 0; a < 3; ++a) bounded += std::isfinite(f.region.lo[a]) || std::isfinite(f.region.hi[a]);
      EXPECT_GE(bounded, 2) << "seed " << seed;
    }
  }
}

TEST(BinningFrame, RetriesInSlabsWhenAGroupOverflowsAndTestsUncuttableSlabsOnTheHost) {
  BinningModel small(smallDevice());
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0, 1);
  // 100 boxes in one cell of the scene's grid (two far boxes set its size): more entries than a group holds.
  std::vector<Aabb> dense{testing::box(100, 100, 100, 101, 101, 101), testing::box(-1, -1, -1, 0, 0, 0)};
  for (int i = 0; i < 100; ++i) {
    const float x = u(rng), y = u(rng), z = u(rng);
    dense.push_back(testing::box(x, y, z, x + 0.05f, y + 0.05f, z + 0.05f));
  }
  BinningFrameStats stats;
  EXPECT_EQ(framePairs(small, dense, &stats), bruteForce(dense));
  EXPECT_GT(stats.retries, 0u);
  const std::vector<Aabb> stacked(100, testing::box(7, 7, 7, 7, 7, 7));  // no cut separates them
  EXPECT_EQ(framePairs(small, stacked, &stats), bruteForce(stacked));
  EXPECT_EQ(stats.frames, 0u);
}

TEST(BinningFrame, RechecksQuantizedPairsAndDropsTheFalseOnes) {
  // Boxes a hair apart: their keys touch after the outward rounding, the floats do not.
  std::vector<Aabb> boxes;
  for (int i = 0; i < 200; ++i) {
    const float x = static_cast<float>(i) * 0.5f;
    boxes.push_back(testing::box(x, 0, 0, std::nextafter(x + 0.5f, 0.0f), 1, 1));
  }
  BinningModel built(builtBinningParams());
  BinningFrameStats stats;
  EXPECT_EQ(framePairs(built, boxes, &stats), bruteForce(boxes));
  EXPECT_TRUE(bruteForce(boxes).empty());
  EXPECT_GT(stats.falsePositives, 0u);
}

TEST(BinningFrame, SendsBoxesLongerThanTheCellsToTheHostsExactPath) {
  // Five outliers among 3000 boxes (3000 / 256 = 11 may go to the host an axis).
  auto boxes = testing::scatteredBoxes(3000, 3, -50, 50, 0.5f, 2.0f);
  for (int i = 0; i < 5; ++i) boxes[static_cast<std::size_t>(i) * 500] = testing::box(-60, -1, -60, 60, 1, 60);
  BinningModel built(builtBinningParams());
  BinningFrameStats stats;
  EXPECT_EQ(framePairs(built, boxes, &stats), bruteForce(boxes));
  EXPECT_EQ(stats.hostBoxes, 5u);
  EXPECT_EQ(stats.boxesSent, 2995u) << "each other box once";
  // Without outliers every box goes to the device.
  boxes = testing::scatteredBoxes(3000, 4, -50, 50, 0.5f, 2.0f);
  EXPECT_EQ(framePairs(built, boxes, &stats), bruteForce(boxes));
  EXPECT_EQ(stats.hostBoxes, 0u);
}

TEST(BinningFrame, RefusesNaNAndInvertedBoxesNamingThem) {
  BinningModel built(builtBinningParams());
  auto boxes = testing::scatteredBoxes(10, 1, 0, 10, 0.5f, 1.0f);
  boxes[4].min[1] = std::nanf("");
  try {
    framePairs(built, boxes);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "object 4: NaN coordinate on axis y");
  }
  boxes[4] = testing::box(1, 1, 1, 0, 2, 2);
  try {
    framePairs(built, boxes);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "object 4: min 1 > max 0 on axis x");
  }
  // Both zeros are one coordinate, as everywhere in the library.
  boxes[4] = Aabb{{0.0f, 1, 1}, {-0.0f, 2, 2}};
  EXPECT_NO_THROW(framePairs(built, boxes));
}

TEST(BinningFrame, IsABroadPhaseOnAFrameDevice) {
  BinningModel built(builtBinningParams());
  BroadPhase bp(built);
  const auto boxes = testing::scatteredBoxes(2000, 9, 0, 50, 0.3f, 2.5f);
  std::vector<Pair> out;
  bp.findPairs(boxes, out);
  EXPECT_EQ(sorted(out), bruteForce(boxes));
  EXPECT_EQ(bp.stats().boxesSent, boxes.size());
  EXPECT_GT(bp.stats().cycles, 0u);
  const std::vector<KeyBox> keys(3);
  EXPECT_THROW(bp.findPairs(keys, out), std::logic_error);
}

}  // namespace
}  // namespace bpaccel
