// The kept grid: when it still serves a frame, and frames of a moving scene
// through one BinningFrame, exact whichever grid each frame took.

#include <gtest/gtest.h>

#include <random>

#include "broad_phase/binning_frame.hpp"
#include "broad_phase/steady_grid.hpp"
#include "core/cpu_features.hpp"
#include "device/binning/binning_model.hpp"
#include "scenes.hpp"

namespace bpaccel {
namespace {

using testing::bruteForce;
using testing::sorted;

AxisBounds boundsOf(std::array<double, 3> lo, std::array<double, 3> hi) {
  AxisBounds b;
  b.lo = lo, b.hi = hi;
  return b;
}

TEST(SteadyGrid, ServesWhileItCoversTheBoxesWithCellsAtMostASixteenthLonger) {
  BinningParams p;
  p.keyWidth = 16, p.cellBits = 4;
  const std::array<double, 3> edge{1, 1, 1};
  const AxisBounds scene = boundsOf({0, 0, 0}, {10, 10, 10});
  const KeyGrid kept = gridFor(p, scene, edge);
  EXPECT_TRUE(SteadyGrid::serves(kept, kept, scene));
  // Boxes moved a little inwards: the fresh grid's cells are a little shorter.
  const AxisBounds inside = boundsOf({0.2, 0, 0}, {9.9, 10, 10});
  EXPECT_TRUE(SteadyGrid::serves(kept, gridFor(p, inside, edge), inside));
  // A box more than 1/16 of a cell (one float unit here) beyond the kept grid on one side, then the other.
  const AxisBounds below = boundsOf({0, -0.07, 0}, {10, 10, 10});
  EXPECT_FALSE(SteadyGrid::serves(kept, gridFor(p, below, edge), below));
  const double end = kept.origin[2] + (kept.top[2] + 1) * kept.unit[2];
  const AxisBounds above = boundsOf({0, 0, 0}, {10, 10, end + 0.07});
  // Within 1/16 of a cell of either end: their keys are clamped into the end cells.
  const AxisBounds edges = boundsOf({-0.06, 0, 0}, {10, 10, end + 0.06});
  EXPECT_TRUE(SteadyGrid::serves(kept, gridFor(p, edges, edge), edges));
  EXPECT_FALSE(SteadyGrid::serves(kept, gridFor(p, above, edge), above));
  // The scene shrank to a quarter: the kept cells are four times what a fresh grid needs.
  const AxisBounds shrunk = boundsOf({0, 0, 0}, {2.5, 2.5, 2.5});
  EXPECT_FALSE(SteadyGrid::serves(kept, gridFor(p, shrunk, {0.1, 0.1, 0.1}), shrunk));
}

TEST(SteadyGrid, TakesOnePassOnTheKeptGridForAMovingSceneAndStaysExact) {
  if (!cpuHasAvx2()) GTEST_SKIP() << "the one pass is AVX2 code";
  BinningModel device(builtBinningParams());
  BinningFrame frame(device);
  // Two boxes that never move hold the scene's bounds; the others move a little every frame, within them.
  std::vector<Aabb> boxes = testing::scatteredBoxes(1500, 3, 1, 58, 0.5f, 1.0f);
  boxes.push_back(testing::box(0, 0, 0, 1, 1, 1));
  boxes.push_back(testing::box(59, 59, 59, 60, 60, 60));
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> step(-0.05f, 0.05f);
  int onePass = 0;
  for (int f = 0; f < 12; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    for (std::size_t i = 0; i < 1500; ++i)
      for (int a = 0; a < 3; ++a) {
        const float d = step(rng);
        if (boxes[i].min[a] + d > 1 && boxes[i].max[a] + d < 59) boxes[i].min[a] += d, boxes[i].max[a] += d;
      }
    // At frame 6 one box is far away, at frame 7 it is back.
    const Aabb home = boxes[0];
    if (f == 6) boxes[0] = testing::box(200, 200, 200, 201, 201, 201);
    std::vector<Pair> out;
    frame.findPairs(boxes, out);
    EXPECT_EQ(sorted(out), bruteForce(boxes));
    // Not on the first frame (nothing kept), at frame 6 (the far box outside the kept grid) nor at 7 (the
    // kept grid, frame 6's, has cells over three times a fresh one's).
    EXPECT_EQ(frame.stats().onePass, f > 0 && f != 6 && f != 7);
    onePass += frame.stats().onePass;
    if (f == 6) boxes[0] = home;
  }
  EXPECT_GE(onePass, 9);
}

}  // namespace
}  // namespace bpaccel
