// The host's grid for the binning device: the vector key conversion against
// the scalar one, and the extent survey against its rule written plainly.

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>
#include <optional>
#include <random>

#include "broad_phase/binning_grid.hpp"
#include "core/cpu_features.hpp"

namespace bpaccel {
namespace {

KeyGrid randomGrid(std::mt19937& rng, unsigned keyWidth) {
  std::uniform_real_distribution<double> origin(-100, 100), unit(0.001, 2);
  KeyGrid g;
  g.shift = keyWidth - 4;
  for (int a = 0; a < 3; ++a) {
    g.origin[a] = origin(rng);
    g.unit[a] = unit(rng);
    g.scale[a] = 1 / g.unit[a];
    g.dims[a] = 1 + rng() % 16;
    g.top[a] = std::min(std::ldexp(double(g.dims[a]), int(g.shift)), std::ldexp(1.0, int(keyWidth))) - 1;
  }
  return g;
}

TEST(QuantizeAll, GivesQuantizesKeysBitForBitForEveryCountOrderAndGridEdge) {
  std::mt19937 rng(5);
  for (unsigned keyWidth : {9u, 12u, 16u, 31u, 32u}) {  // 32: keys above an int32, the scalar loop's
    for (std::size_t n : {0, 1, 2, 3, 7, 100, 1000}) {
      const KeyGrid g = randomGrid(rng, keyWidth);
      std::vector<Aabb> boxes(n);
      for (std::size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
          const double span = g.unit[a] * (g.top[a] + 1);
          // Inside, beyond both ends, and exactly on key boundaries, where rounding up and down differ.
          std::uniform_real_distribution<double> at(-0.2 * span, 1.2 * span);
          double lo = at(rng), hi = lo + std::abs(at(rng)) * 0.01;
          if (i % 3 == 0) lo = std::floor(lo / g.unit[a]) * g.unit[a], hi = std::ceil(hi / g.unit[a]) * g.unit[a];
          if (i % 50 == 7 && a == static_cast<int>(i % 3)) hi = lo + 0.5 * span;  // across several cells
          boxes[i].min[a] = static_cast<float>(g.origin[a] + lo);
          boxes[i].max[a] = std::max(boxes[i].min[a], static_cast<float>(g.origin[a] + hi));
        }
      std::vector<std::uint32_t> ids(n);
      std::iota(ids.begin(), ids.end(), 0u);
      std::shuffle(ids.begin(), ids.end(), rng);
      std::vector<KeyBox> keys(n);
      const bool allFit = quantizeAll(g, boxes, ids, keys);
      bool wantAllFit = true;
      for (std::size_t k = 0; k < n; ++k) {
        const KeyBox want = quantize(g, boxes[ids[k]]);
        wantAllFit = wantAllFit && fitsCells(g, want);
        for (int a = 0; a < 3; ++a) {
          ASSERT_EQ(keys[k].min[a], want.min[a]) << "width " << keyWidth << " n " << n << " k " << k << " axis " << a;
          ASSERT_EQ(keys[k].max[a], want.max[a]) << "width " << keyWidth << " n " << n << " k " << k << " axis " << a;
        }
      }
      EXPECT_EQ(allFit, wantAllFit) << "width " << keyWidth << " n " << n;
    }
  }
}

/// surveyExtents' rule, plainly: per axis the finite extents sorted longest first; q = the binary exponent
/// of the (n / 256 + 1)-th longest (0 when there are not that many); the reach = the longest extent whose
/// exponent is at most q + 1; every box is within when no finite extent is above that and none is infinite.
ExtentSurvey plainSurvey(const BinningParams& p, const std::vector<Aabb>& boxes) {
  const auto exponent = [](double e) { return static_cast<int>((std::bit_cast<std::uint64_t>(e) >> 52) & 0x7ff); };
  const double keys = std::ldexp(1.0, static_cast<int>(p.maxShift()));
  ExtentSurvey s;
  s.allWithin = true;
  for (const Aabb& b : boxes) s.bounds.add(b);
  for (int a = 0; a < 3; ++a) {
    std::vector<double> finite;
    for (const Aabb& b : boxes) {
      const double e = double{b.max[a]} - double{b.min[a]};
      if (std::isfinite(e)) finite.push_back(e);
      else s.allWithin = false;
    }
    std::sort(finite.rbegin(), finite.rend());
    const std::size_t outliers = boxes.size() / 256;
    const int q = outliers < finite.size() ? exponent(finite[outliers]) : 0;
    double reach = 0;
    for (double e : finite)
      if (exponent(e) <= q + 1) reach = std::max(reach, e);
      else s.allWithin = false;
    s.cellEdge[a] = reach * keys / (keys - 4);
  }
  return s;
}

TEST(SurveyExtents, FollowsItsRuleOnScenesWithAndWithoutOutliers) {
  const BinningParams p;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> centre(-50, 50), size(0.5f, 3.2f);
  for (std::size_t n : {0, 1, 2, 3, 255, 256, 700, 3000}) {
    for (int kind = 0; kind < 6; ++kind) {
      std::vector<Aabb> boxes(n);
      for (std::size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
          float e = size(rng);
          if (kind == 1 && i % 400 == 5) e *= 1000;         // a few outliers: below n / 256 or not, by n
          if (kind == 2 && i % 2 == 0) e *= 0.01f;          // two size classes far apart
          if (kind == 3) e = 0;                             // all flat
          if (kind == 4 && i % 3 == 0) e = size(rng) * 1.6f; // extents near the top buckets' floor
          boxes[i].min[a] = centre(rng);
          boxes[i].max[a] = boxes[i].min[a] + e;
        }
      if (kind == 5 && n > 0) boxes[n / 2].max[1] = HUGE_VALF;  // an infinite box
      const ExtentSurvey got = surveyExtents(p, boxes), want = plainSurvey(p, boxes);
      const std::string what = "n " + std::to_string(n) + " kind " + std::to_string(kind);
      EXPECT_EQ(got.allWithin, want.allWithin) << what;
      for (int a = 0; a < 3; ++a) {
        EXPECT_EQ(got.cellEdge[a], want.cellEdge[a]) << what << " axis " << a;
        EXPECT_EQ(got.bounds.lo[a], want.bounds.lo[a]) << what << " axis " << a;
        EXPECT_EQ(got.bounds.hi[a], want.bounds.hi[a]) << what << " axis " << a;
      }
    }
  }
}

TEST(SurveyCommonOnGrid, GivesSurveyExtentsAndQuantizesResultsInOnePassOrDeclines) {
  if (!cpuHasAvx2()) GTEST_SKIP() << "the one pass is AVX2 code";
  BinningParams p;
  p.keyWidth = 16, p.cellBits = 4;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> centre(-50, 50), size(0.5f, 2.0f);
  int onePass = 0;
  for (std::size_t n : {0, 1, 2, 3, 255, 257, 2000})
    for (int kind = 0; kind < 6; ++kind) {
      std::vector<Aabb> boxes(n);
      for (std::size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
          float e = size(rng);
          if (kind == 1 && i % 400 == 5) e *= 1000;  // outliers, below n / 256 or not, by n
          boxes[i].min[a] = centre(rng);
          boxes[i].max[a] = boxes[i].min[a] + e;
        }
      if (kind == 2 && n > 0) boxes[n - 1].max[2] = HUGE_VALF;             // infinite, the last box
      if (kind == 3 && n > 1) boxes[n / 2].min[0] = boxes[n / 2].max[0] + 1;  // inverted
      if (kind == 4 && n > 0) boxes[n - 1].max[1] = NAN;                    // NaN, the last box
      const std::string what = "n " + std::to_string(n) + " kind " + std::to_string(kind);
      const bool bad = (kind == 3 && n > 1) || (kind == 4 && n > 0);
      const ExtentSurvey want = bad ? ExtentSurvey{} : surveyExtents(p, boxes);
      const KeyGrid g = randomGrid(rng, p.keyWidth);
      std::vector<KeyBox> keys(n);
      for (bool rightGuess : {true, false}) {
        std::array<double, 3> guess = want.topFloor;
        if (!rightGuess) guess[rng() % 3] *= 2;
        const std::optional<CommonPass> got = surveyCommonOnGrid(p, boxes, g, guess, keys);
        // It declines a bad box (surveyExtents names it), a wrong guess and any frame surveyExtents finds uncommon.
        if (bad || !rightGuess || n < 2 || kind == 2) {
          EXPECT_FALSE(got) << what << " guess " << rightGuess;
          continue;
        }
        if (kind == 1 && !want.allWithin) EXPECT_FALSE(got) << what;
        if (!got) continue;
        onePass += 1;
        EXPECT_TRUE(got->survey.allWithin) << what;
        bool wantFit = true;
        for (int a = 0; a < 3; ++a) {
          EXPECT_EQ(got->survey.cellEdge[a], want.cellEdge[a]) << what << " axis " << a;
          EXPECT_EQ(got->survey.bounds.lo[a], want.bounds.lo[a]) << what << " axis " << a;
          EXPECT_EQ(got->survey.bounds.hi[a], want.bounds.hi[a]) << what << " axis " << a;
          EXPECT_EQ(got->survey.topFloor[a], want.topFloor[a]) << what << " axis " << a;
        }
        for (std::size_t k = 0; k < n; ++k) {
          const KeyBox key = quantize(g, boxes[k]);
          wantFit = wantFit && fitsCells(g, key);
          ASSERT_EQ(keys[k].min, key.min) << what << " box " << k;
          ASSERT_EQ(keys[k].max, key.max) << what << " box " << k;
        }
        EXPECT_EQ(got->keysFit, wantFit) << what;
      }
    }
  EXPECT_GE(onePass, 4) << "the one pass never ran: the test compared nothing";
}

}  // namespace
}  // namespace bpaccel
