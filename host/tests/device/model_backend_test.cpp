#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/keys.hpp"
#include "device/backend.hpp"
#include "device/model_backend.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

TEST(ModelBackend, BipartiteRunsTestOnlyAcrossTheSplitAndRefuseABadSplit) {
  ModelBackend stream(DeviceParams::stream(3, 64, 3, 4));
  DeviceParams seedParams = DeviceParams::seed(3, 63, 3);
  ModelBackend seed(seedParams);
  const auto boxes = adversarialScenes(40, 4).at(1).second;  // clusters: many hits
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  std::vector<Pair> pairs;
  RunStats stats;
  EXPECT_THROW(seed.runBipartite(keys, 5, pairs, stats), std::logic_error);
  EXPECT_THROW(stream.runBipartite(keys, 0, pairs, stats), std::invalid_argument);
  EXPECT_THROW(stream.runBipartite(keys, 40, pairs, stats), std::invalid_argument);
  EXPECT_TRUE(pairs.empty());
  for (std::size_t split = 1; split < 40; ++split) {
    pairs.clear();
    stats = {};
    stream.runBipartite(keys, split, pairs, stats);
    std::vector<Pair> across;
    for (const Pair& p : bruteForce(boxes))
      if (p.first < split && p.second >= split) across.push_back(p);
    EXPECT_EQ(sorted(pairs), across) << "split " << split;
    EXPECT_EQ(stats.issueCycles, scheduleIssueCycles(40, 3, split)) << "split " << split;
    EXPECT_EQ(stats.cycles, 4 + stats.issueCycles + 3 + 1) << "split " << split;  // + the cell's end
  }
}

TEST(ScheduleIssueCycles, MatchesThePlainSumOverBlocks) {
  for (std::uint64_t m = 1; m <= 40; ++m)
    for (std::uint64_t n = 0; n <= 300; ++n) {
      std::uint64_t sum = 0;
      for (std::uint64_t b = 0; n >= 2 && b * m <= n - 2; ++b) sum += n - 1 - b * m;
      ASSERT_EQ(scheduleIssueCycles(n, m), sum) << "m=" << m << " n=" << n;
      // Bipartite: the A blocks only, each until lane 0 reaches n-1 or past its prefix's 2m-1 and B.
      for (std::uint64_t split = 1; split < n; ++split) {
        std::uint64_t bipartite = 0;
        for (std::uint64_t b = 0; b * m <= split - 1; ++b) bipartite += std::min(n - 1 - b * m, 2 * m - 1 + n - split);
        ASSERT_EQ(scheduleIssueCycles(n, m, split), bipartite) << "m=" << m << " n=" << n << " split=" << split;
      }
    }
  EXPECT_THROW(scheduleIssueCycles(10, 4, 10), std::invalid_argument);
}

TEST(ModelBackend, RefusesKeysWiderThanItsDeviceNamingTheBox) {
  DeviceParams narrowParams = DeviceParams::stream(2, 8, 3, 4, true);
  narrowParams.batchCells = 8;
  narrowParams.keyWidth = 16;
  ModelBackend narrow(narrowParams);
  std::vector<KeyBox> boxes(3, KeyBox{{1, 2, 3}, {4, 5, 6}});
  boxes[2].max[1] = 0x10000;
  std::vector<Pair> out;
  RunStats stats;
  try {
    narrow.run(boxes, out, stats);
    FAIL() << "a 17-bit key went to a 16-bit device";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("box 2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("axis 1"), std::string::npos) << e.what();
  }
  for (const unsigned bad : {0u, 33u}) {
    narrowParams.keyWidth = bad;
    EXPECT_THROW(ModelBackend{narrowParams}, std::invalid_argument);
  }
}
