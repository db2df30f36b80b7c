#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include "broad_phase/broad_phase.hpp"
#include "device/cpu_backend.hpp"
#include "partition/kd_tree.hpp"
#include "core/keys.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

TEST(KdTree, LeavesRespectTheCellSizeWhenSplitsExistAndPartitionSpace) {
  // Small boxes spread thinly: planes rarely cut them, so every cell can split down.
  const std::vector<Aabb> boxes = scatteredBoxes(2000, 3, -100, 100, 0, 0.5f);
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  KdTree tree;
  for (std::size_t cell : {8u, 32u, 128u}) {
    tree.build(keys, cell, {});
    std::size_t maxLeaf = 0, total = 0;
    for (const auto& leaf : tree.cells()) {
      maxLeaf = std::max<std::size_t>(maxLeaf, leaf.count);
      total += leaf.count;
      // Every box of a leaf touches the leaf's region.
      for (std::uint32_t id : tree.items(leaf))
        for (int a = 0; a < 3; ++a) {
          EXPECT_LT(keys[id].min[a], leaf.hi[a]);
          EXPECT_GE(std::uint64_t{keys[id].max[a]}, leaf.lo[a]);
        }
    }
    EXPECT_LE(maxLeaf, cell) << "uniform small boxes should always split down to the cell size";
    EXPECT_LT(total, 2 * keys.size()) << "straddling boxes must not blow up the tree";
    // Random points fall in exactly one leaf: the regions partition key space.
    std::mt19937 rng(cell);
    for (int t = 0; t < 2000; ++t) {
      const std::array<std::uint32_t, 3> p{static_cast<std::uint32_t>(rng()), static_cast<std::uint32_t>(rng()),
                                           static_cast<std::uint32_t>(rng())};
      int holders = 0;
      for (const auto& leaf : tree.cells()) holders += leaf.contains(p);
      EXPECT_EQ(holders, 1);
    }
  }
}

TEST(KdTree, MemoryStaysLinearInTheObjectsHoweverDeepTheTree) {
  // 20,000 small boxes at cell size 2: about 14 levels. Keeping every level's
  // item lists would hold about n per level; the tree must hold O(n) in all.
  std::mt19937 gen(4);
  std::uniform_real_distribution<float> pos(-1000, 1000);
  std::vector<Aabb> boxes(20000);
  for (auto& b : boxes) {
    const float x = pos(gen), y = pos(gen), z = pos(gen);
    b = box(x, y, z, x + 0.1f, y + 0.1f, z + 0.1f);
  }
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  KdTree tree;
  tree.build(keys, 2, {});
  ASSERT_GT(tree.cells().size(), 8000u);  // the tree really is deep
  EXPECT_LE(tree.storedItems(), 8 * keys.size());
}

TEST(KdTree, ReportsAPairInSeveralLeavesOnlyOnce) {
  // Two big overlapping boxes straddle every plane among many small ones, so
  // they share many leaves; the reference-point rule must keep one copy.
  std::vector<Aabb> boxes = adversarialScenes(400, 9).front().second;
  boxes.push_back(box(-200, -200, -200, 200, 200, 200));
  boxes.push_back(box(-150, -150, -150, 150, 150, 150));
  CpuBackend cpu;
  BroadPhase bp(cpu, {.cellSize = 8});
  std::vector<Pair> pairs;
  bp.findPairs(boxes, pairs);
  std::size_t sharing = 0;
  for (const auto& leaf : bp.partition().cells()) {
    const auto items = bp.partition().items(leaf);
    const bool a = std::find(items.begin(), items.end(), 400u) != items.end();
    const bool b = std::find(items.begin(), items.end(), 401u) != items.end();
    sharing += a && b;
  }
  EXPECT_GT(sharing, 1u) << "the test scene should put the big pair in several leaves";
  EXPECT_EQ(std::count(pairs.begin(), pairs.end(), Pair{400, 401}), 1);
  EXPECT_EQ(sorted(pairs), bruteForce(boxes));
}

TEST(KdTree, CarriedAndGatheredLayoutsGiveTheSameLeavesAndPackedBoxes) {
  for (unsigned seed : {1u, 2u, 3u}) {
    for (const auto& [name, boxes] : adversarialScenes(900, seed)) {
      std::vector<KeyBox> keys;
      toKeys(boxes, keys);
      for (std::size_t cell : {2u, 16u, 100u}) {
        struct Seen {
          KdTree::Leaf leaf;
          std::vector<std::uint32_t> items;
          std::vector<KeyBox> packed;
        };
        std::vector<Seen> gathered, carried;
        KdTree a, b;
        a.build(keys, cell, [&](const KdTree::Leaf& l, auto items, auto packed) {
          EXPECT_TRUE(packed.empty());
          gathered.push_back({l, {items.begin(), items.end()}, {}});
        }, KdTree::Layout::Gathered);
        b.build(keys, cell, [&](const KdTree::Leaf& l, auto items, auto packed) {
          carried.push_back({l, {items.begin(), items.end()}, {packed.begin(), packed.end()}});
        }, KdTree::Layout::Carried);
        const std::string label = name + " cell " + std::to_string(cell);
        ASSERT_EQ(gathered.size(), carried.size()) << label;
        for (std::size_t k = 0; k < gathered.size(); ++k) {
          EXPECT_EQ(gathered[k].items, carried[k].items) << label;
          EXPECT_EQ(gathered[k].leaf.lo, carried[k].leaf.lo) << label;
          EXPECT_EQ(gathered[k].leaf.hi, carried[k].leaf.hi) << label;
          ASSERT_EQ(carried[k].packed.size(), carried[k].items.size()) << label;
          for (std::size_t t = 0; t < carried[k].items.size(); ++t)
            EXPECT_TRUE(carried[k].packed[t].min == keys[carried[k].items[t]].min &&
                        carried[k].packed[t].max == keys[carried[k].items[t]].max)
                << label;
        }
      }
    }
  }
}
