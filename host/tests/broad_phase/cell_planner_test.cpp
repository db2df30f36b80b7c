#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "broad_phase/cell_planner.hpp"
#include "broad_phase/device_cell.hpp"

using namespace bpaccel;

namespace {

// Every pair (i < j) of a cell of n boxes, how often the plan's runs test it
// and how often their decoding keeps it, from the runs alone: the chunks'
// index ranges, the keep bits as keepPairs reads them, and a bipartite run
// testing its cross pairs only.
struct Coverage {
  std::map<std::pair<std::size_t, std::size_t>, int> tested, kept;
};

Coverage cover(std::size_t n, const ChunkPlan& plan) {
  Coverage c;
  const auto range = [&](std::size_t p) {
    return std::pair(p * plan.chunkSize, std::min(n, (p + 1) * plan.chunkSize));
  };
  for (const ChunkRun& run : plan.runs) {
    std::vector<std::size_t> items;  // scene indices in the run's order: first chunk, then second
    const auto [a0, a1] = range(run.first);
    for (std::size_t i = a0; i < a1; ++i) items.push_back(i);
    const std::size_t splitAt = items.size();
    if (!run.alone()) {
      const auto [b0, b1] = range(run.second);
      for (std::size_t i = b0; i < b1; ++i) items.push_back(i);
    }
    for (std::size_t x = 0; x < items.size(); ++x)
      for (std::size_t y = x + 1; y < items.size(); ++y) {
        const bool cross = x < splitAt && y >= splitAt;
        if (run.bipartite && !cross) continue;  // the device tests only across the split
        const auto pair = std::pair(items[x], items[y]);
        ++c.tested[pair];
        const int kind = cross ? kCross : (x < splitAt ? kFirstInside : kSecondInside);
        c.kept[pair] += (run.keep & kind) != 0;
      }
  }
  return c;
}

}  // namespace

TEST(CellPlanner, EveryPairOfAnOversizedCellIsKeptExactlyOnce) {
  ChunkPlan plan;
  for (const bool bipartite : {false, true})
    for (std::size_t capacity = 2; capacity <= 12; ++capacity)
      for (std::size_t n = capacity + 1; n <= 4 * capacity + 3; ++n) {
        const std::string label = (bipartite ? "bipartite" : "triangular") + std::string(" n ") + std::to_string(n) +
                                  " capacity " + std::to_string(capacity);
        planChunks(n, capacity, bipartite, plan);
        EXPECT_EQ(plan.chunkSize, capacity / 2) << label;
        EXPECT_EQ(plan.chunks, (n + plan.chunkSize - 1) / plan.chunkSize) << label;
        const Coverage c = cover(n, plan);
        for (std::size_t i = 0; i < n; ++i)
          for (std::size_t j = i + 1; j < n; ++j) {
            ASSERT_EQ(c.kept.count({i, j}) ? c.kept.at({i, j}) : 0, 1) << label << " pair " << i << " " << j;
            // With bipartite runs each pair is also tested only once.
            if (bipartite) ASSERT_EQ(c.tested.at({i, j}), 1) << label << " pair " << i << " " << j;
          }
        for (const ChunkRun& run : plan.runs) {
          const std::size_t first = std::min(plan.chunkSize, n - run.first * plan.chunkSize);
          const std::size_t second = run.alone() ? 0 : std::min(plan.chunkSize, n - run.second * plan.chunkSize);
          EXPECT_LE(first + second, capacity) << label;  // every run fits the device
          EXPECT_EQ(run.bipartite, bipartite && !run.alone()) << label;
        }
      }
}

TEST(CellPlanner, TheCheckCatchesAPlanThatDropsAPairOrKeepsOneTwice) {
  ChunkPlan plan;
  planChunks(20, 8, false, plan);
  ChunkPlan dropped = plan;
  dropped.runs.back().keep &= ~kSecondInside;  // the last chunk's inside pairs kept nowhere
  ChunkPlan doubled = plan;
  doubled.runs.front().keep |= kSecondInside;  // chunk 1's inside pairs kept twice
  for (const ChunkPlan* bad : {&dropped, &doubled}) {
    const Coverage c = cover(20, *bad);
    bool allOnce = true;
    for (std::size_t i = 0; i < 20; ++i)
      for (std::size_t j = i + 1; j < 20; ++j) allOnce = allOnce && c.kept.count({i, j}) && c.kept.at({i, j}) == 1;
    EXPECT_FALSE(allOnce);
  }
}

TEST(CellPlanner, RefusesACellThatNeedsNoChunks) {
  ChunkPlan plan;
  EXPECT_THROW(planChunks(8, 8, true, plan), std::invalid_argument);
  EXPECT_THROW(planChunks(9, 1, true, plan), std::invalid_argument);
}
