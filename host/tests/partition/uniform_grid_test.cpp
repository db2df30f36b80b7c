#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <optional>
#include <random>

#include "device/model_backend.hpp"
#include "device/cpu_backend.hpp"
#include "device/built_device.hpp"
#include "device/backend.hpp"
#include "bpaccel_params.h"
#include "broad_phase/broad_phase.hpp"
#include "core/keys.hpp"
#include "scenes.hpp"
#include "partition/uniform_grid.hpp"
#include "core/thread_pool.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

const UniformGrid& gridOf(const BroadPhase& bp) { return dynamic_cast<const UniformGrid&>(bp.partition()); }

void expectExactOnGrid(Backend& backend, const std::vector<Aabb>& boxes, std::size_t cell, const std::string& what,
                       const std::vector<Pair>& exact) {
  BroadPhase bp(backend, {.cellSize = cell, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 1});
  std::vector<Pair> pairs;
  bp.findPairs(boxes, pairs);
  EXPECT_EQ(sorted(pairs), exact) << what << " backend " << backend.name() << " cell " << cell;
}

void expectExactOnGrid(Backend& backend, const std::vector<Aabb>& boxes, std::size_t cell, const std::string& what) {
  expectExactOnGrid(backend, boxes, cell, what, bruteForce(boxes));
}

// The partition's contract: the cells' regions cover key space without
// overlap, and a box is in a cell exactly when it touches the cell's region.
void expectCellsPartitionSpaceAndHoldExactlyTheirBoxes(const Partition& p, const std::vector<KeyBox>& keys,
                                                       const std::string& what) {
  std::vector<std::vector<char>> in(p.cells().size(), std::vector<char>(keys.size(), 0));
  for (std::size_t c = 0; c < p.cells().size(); ++c)
    for (std::uint32_t id : p.items(p.cells()[c])) {
      ASSERT_LT(id, keys.size()) << what;
      EXPECT_FALSE(in[c][id]) << what << ": box " << id << " twice in cell " << c;
      in[c][id] = 1;
    }
  for (std::size_t c = 0; c < p.cells().size(); ++c) {
    const Cell& cell = p.cells()[c];
    for (std::size_t id = 0; id < keys.size(); ++id) {
      bool touches = true;
      for (int a = 0; a < 3; ++a) touches = touches && keys[id].min[a] < cell.hi[a] && keys[id].max[a] >= cell.lo[a];
      EXPECT_EQ(static_cast<bool>(in[c][id]), touches) << what << ": box " << id << " cell " << c;
    }
  }
  std::mt19937 rng(7);
  std::vector<std::array<std::uint32_t, 3>> points;
  for (int t = 0; t < 300; ++t) points.push_back({static_cast<std::uint32_t>(rng()), static_cast<std::uint32_t>(rng()),
                                                   static_cast<std::uint32_t>(rng())});
  // The boxes' own corners: where planes and boxes meet.
  for (const KeyBox& k : keys) {
    points.push_back(k.min);
    points.push_back(k.max);
  }
  points.push_back({0, 0, 0});
  points.push_back({~0u, ~0u, ~0u});
  for (const auto& point : points) {
    int holders = 0;
    for (const Cell& cell : p.cells()) holders += cell.contains(point);
    EXPECT_EQ(holders, 1) << what;
  }
}

}  // namespace

TEST(UniformGrid, ModelAndCpuAreExactOnAdversarialScenesForEveryCellSize) {
  ModelBackend model(builtDeviceParams());
  CpuBackend cpu;
  for (std::size_t n : {0u, 1u, 2u, 7u, 150u, 600u})
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 11)) {
      const auto exact = bruteForce(boxes);  // once a scene: the sanitizer build runs this test too
      for (std::size_t cell : {1u, 2u, 3u, 5u, 8u, 16u, 32u, 64u, 256u}) {
        expectExactOnGrid(model, boxes, cell, name + " n=" + std::to_string(n), exact);
        expectExactOnGrid(cpu, boxes, cell, name + " n=" + std::to_string(n), exact);
      }
    }
}

TEST(UniformGrid, CellsPartitionKeySpaceAndHoldEveryBoxTheyTouch) {
  std::size_t gridded = 0;
  for (const auto& [name, boxes] : adversarialScenes(300, 4)) {
    std::vector<KeyBox> keys;
    toKeys(boxes, keys);
    for (std::size_t cell : {2u, 16u, 64u}) {
      UniformGrid grid;
      std::size_t handed = 0;
      bool sameItems = true, packedAreTheItemsBoxes = true;
      grid.build(keys, cell, [&](const Cell& c, auto items, auto packed) {
        sameItems = sameItems && grid.cells().at(handed).begin == c.begin &&
                    std::equal(items.begin(), items.end(), grid.items(c).begin(), grid.items(c).end());
        if (grid.fellBack()) return;
        packedAreTheItemsBoxes = packedAreTheItemsBoxes && packed.size() == items.size() &&
                                 packed.data() == grid.packed(c).data();
        for (std::size_t t = 0; packedAreTheItemsBoxes && t < items.size(); ++t)
          packedAreTheItemsBoxes = packed[t].min == keys[items[t]].min && packed[t].max == keys[items[t]].max;
        ++handed;
      });
      const std::string label = name + " cell " + std::to_string(cell);
      if (grid.fellBack()) continue;  // the tree's own tests cover its cells
      ++gridded;
      EXPECT_TRUE(sameItems) << label << ": cells are handed over as the grid keeps them, in order";
      EXPECT_TRUE(packedAreTheItemsBoxes) << label << ": each cell's packed boxes are its items' boxes, in order";
      EXPECT_TRUE(grid.cellsOutliveBuild()) << label;
      EXPECT_EQ(handed, grid.cells().size()) << label;
      expectCellsPartitionSpaceAndHoldExactlyTheirBoxes(grid, keys, label);
    }
  }
  EXPECT_GE(gridded, 15u) << "most adversarial scenes should be gridded, not handed to the tree";
}

TEST(UniformGrid, BelowBitsSayOnWhichAxesEachItemsBoxStartsBelowItsCell) {
  std::size_t gridded = 0, withBits = 0;
  for (const auto& [name, boxes] : adversarialScenes(300, 6)) {
    std::vector<KeyBox> keys;
    toKeys(boxes, keys);
    for (std::size_t cell : {2u, 16u, 64u}) {
      UniformGrid grid;
      grid.build(keys, cell, {});
      const std::string label = name + " cell " + std::to_string(cell);
      if (grid.fellBack()) {
        for (const Cell& c : grid.cells()) EXPECT_TRUE(grid.below(c).empty()) << label << ": the tree has no bits";
        continue;
      }
      ++gridded;
      for (const Cell& c : grid.cells()) {
        const auto items = grid.items(c);
        const auto below = grid.below(c);
        ASSERT_EQ(below.size(), items.size()) << label;
        for (std::size_t t = 0; t < items.size(); ++t) {
          EXPECT_EQ(below[t], belowBits(keys[items[t]].min, c.lo)) << label << " box " << items[t];
          withBits += below[t] != 0;
        }
      }
    }
  }
  EXPECT_GE(gridded, 15u);
  EXPECT_GT(withBits, 0u) << "some straddlers lie in cells above their first";
}

TEST(UniformGrid, OwnsPairFromBelowBitsAgreesWithTheReferencePointInTheRegion) {
  // Any two boxes that touch a region: the bits decide as the point does.
  std::mt19937 rng(5);
  const Cell region{0, 0, {100, 100, 100}, {200, 200, 200}};
  const auto coordinate = [&] { return static_cast<std::uint32_t>(50 + rng() % 200); };
  for (int t = 0; t < 20000; ++t) {
    KeyBox b[2];
    for (KeyBox& k : b)
      for (int a = 0; a < 3; ++a) {
        do {
          k.min[a] = coordinate();
          k.max[a] = k.min[a] + rng() % 120;
        } while (!(k.min[a] < region.hi[a] && k.max[a] >= region.lo[a]));  // touches the region on axis a
      }
    EXPECT_EQ(ownsPair(belowBits(b[0].min, region.lo), belowBits(b[1].min, region.lo)),
              region.contains(referencePoint(b[0], b[1])));
  }
}

TEST(UniformGrid, SaysEachSlabsCellsAreFinalOnlyOnceTheyAreAsTheBuildAtOnceMakesThem) {
  EXPECT_FALSE(UniformGrid().streamsCells()) << "BroadPhase builds the grid in steps and goes through its cells";
  EXPECT_TRUE(KdTree().streamsCells()) << "the tree's first leaf goes to the device before the tree is done";
  EXPECT_TRUE(KdTree().below(Cell{}).empty());
  EXPECT_TRUE(KdTree().packed(Cell{}).empty());
  // What a cell held when a step (or the sink) said it was final must be
  // what it holds after a build at once: items, below() bits and boxes, in
  // the same order.
  struct Held {
    std::vector<std::uint32_t> items;
    std::vector<std::uint8_t> below;
    std::vector<KeyBox> packed;
    bool operator==(const Held& o) const {
      if (items != o.items || below != o.below || packed.size() != o.packed.size()) return false;
      for (std::size_t t = 0; t < packed.size(); ++t)
        if (packed[t].min != o.packed[t].min || packed[t].max != o.packed[t].max) return false;
      return true;
    }
  };
  const auto held = [](const UniformGrid& grid, const Cell& c, std::span<const std::uint32_t> items,
                       std::span<const KeyBox> packed) {
    const auto below = grid.below(c);
    return Held{{items.begin(), items.end()}, {below.begin(), below.end()}, {packed.begin(), packed.end()}};
  };
  std::size_t slabbed = 0;
  for (const auto& [name, boxes] : adversarialScenes(400, 9)) {
    std::vector<KeyBox> keys;
    toKeys(boxes, keys);
    for (std::size_t cell : {1u, 4u, 16u, 64u}) {
      const std::string label = name + " cell " + std::to_string(cell);
      UniformGrid withSink, stepped, whole;
      std::vector<Held> handed, final;
      withSink.build(keys, cell, [&](const Cell& c, auto items, auto packed) {
        handed.push_back(held(withSink, c, items, packed));
      });
      std::size_t steps = 0;
      stepped.buildInSteps(keys, cell, [&](std::size_t finalCells) {
        ++steps;
        EXPECT_GT(finalCells, final.size()) << label << ": each step finishes cells";
        while (final.size() < finalCells) {
          const Cell& c = stepped.cells().at(final.size());
          final.push_back(held(stepped, c, stepped.items(c), stepped.packed(c)));
        }
      });
      whole.build(keys, cell, {});
      ASSERT_EQ(withSink.fellBack(), whole.fellBack()) << label;
      if (whole.fellBack()) continue;
      EXPECT_EQ(steps, whole.resolution()[2]) << label << ": one step a slab";
      slabbed += whole.resolution()[2] > 1;
      ASSERT_EQ(handed.size(), whole.cells().size()) << label << ": every cell once";
      ASSERT_EQ(final.size(), whole.cells().size()) << label << ": the last step finishes every cell";
      for (std::size_t c = 0; c < handed.size(); ++c) {
        const Cell& w = whole.cells()[c];
        const Held expected = held(whole, w, whole.items(w), whole.packed(w));
        EXPECT_TRUE(handed[c] == expected) << label << " cell " << c << ": the sink's cell differs";
        EXPECT_TRUE(final[c] == expected) << label << " cell " << c << ": a step said final too early";
        EXPECT_EQ(withSink.cells()[c].begin, w.begin) << label;
      }
    }
  }
  EXPECT_GE(slabbed, 10u) << "many scenes should have several slabs";
}

TEST(UniformGrid, CellsDoNotDependOnWhichLoopComputedABox) {
  // Four boxes a step with AVX2, then two with SSE2, then one by one: a
  // scene of 4k + 3 boxes, rotated and reversed, sends each box through
  // other loops and lanes. The bounds and n stay, so the planes do, and each
  // cell must hold the same boxes with the same below() bits.
  std::vector<Aabb> boxes = scatteredBoxes(403, 21, -40, 40, 0.5f, 6);
  boxes[5] = box(-30, -30, -30, 30, 2, 3);  // spans more than two cells an axis
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  UniformGrid reference;
  reference.build(keys, 16, {});
  ASSERT_FALSE(reference.fellBack());
  // Per cell: (box, below bits), sorted.
  const auto contents = [](const UniformGrid& grid, const std::vector<std::uint32_t>& original) {
    std::vector<std::vector<std::pair<std::uint32_t, std::uint8_t>>> cells;
    for (const Cell& c : grid.cells()) {
      auto& held = cells.emplace_back();
      for (std::size_t t = 0; t < c.count; ++t) held.emplace_back(original[grid.items(c)[t]], grid.below(c)[t]);
      std::sort(held.begin(), held.end());
    }
    return cells;
  };
  std::vector<std::uint32_t> identity(keys.size());
  std::iota(identity.begin(), identity.end(), 0u);
  const auto expected = contents(reference, identity);
  std::size_t straddled = 0;
  for (const auto& held : expected)
    for (const auto& [id, bits] : held) straddled += bits != 0;
  ASSERT_GT(straddled, 50u) << "the scene must have straddlers";
  for (int variant = 1; variant <= 4; ++variant) {
    std::vector<std::uint32_t> original = identity;  // original[new index] = old index
    if (variant < 4)
      std::rotate(original.begin(), original.begin() + variant, original.end());
    else
      std::reverse(original.begin(), original.end());
    std::vector<KeyBox> moved(keys.size());
    for (std::size_t t = 0; t < keys.size(); ++t) moved[t] = keys[original[t]];
    UniformGrid grid;
    grid.build(moved, 16, {});
    ASSERT_FALSE(grid.fellBack());
    ASSERT_EQ(grid.cells().size(), reference.cells().size()) << variant;
    for (std::size_t c = 0; c < grid.cells().size(); ++c) {
      EXPECT_EQ(grid.cells()[c].lo, reference.cells()[c].lo) << variant;
      EXPECT_EQ(grid.cells()[c].hi, reference.cells()[c].hi) << variant;
    }
    EXPECT_EQ(contents(grid, original), expected) << "variant " << variant;
  }
}

TEST(UniformGrid, AimsAtTwoNOverCellSizeCellsOnAUniformScene) {
  const std::vector<Aabb> boxes = scatteredBoxes(8000, 3, 0, 54, 0.5f, 2.5f);
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  for (std::size_t cell : {16u, 128u, 256u}) {
    UniformGrid grid;
    grid.build(keys, cell, {});
    ASSERT_FALSE(grid.fellBack()) << cell;
    const auto r = grid.resolution();
    const double cells = static_cast<double>(r[0]) * r[1] * r[2], target = 2.0 * 8000 / cell;
    EXPECT_GT(cells, target / 2) << cell;
    EXPECT_LT(cells, target * 2) << cell;
    EXPECT_LE(r[0], r[1] + 1) << "a cubic scene gets cubic cells";
    EXPECT_LE(r[1], r[0] + 1);
    EXPECT_LE(grid.storedItems(), 3 * UniformGrid::kMaxEntriesPerBox * keys.size());
    EXPECT_LE(grid.storedBoxes(), UniformGrid::kMaxEntriesPerBox * keys.size());
  }
}

TEST(UniformGrid, CoversCellsAboveTheCapacityInChunksExactly) {
  // Cells of about 20 boxes on a device that holds 4 or 6: every cell is chunked.
  const std::vector<Aabb> boxes = scatteredBoxes(300, 8, -20, 20, 0.5f, 3);
  for (std::size_t capacity : {2u, 4u, 6u, 16u}) {
    ModelBackend small(DeviceParams::seed(2, capacity, 5));
    BroadPhase bp(small, {.cellSize = 40, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 1});
    std::vector<Pair> pairs;
    bp.findPairs(boxes, pairs);
    EXPECT_FALSE(gridOf(bp).fellBack());
    EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << "capacity " << capacity;
    EXPECT_GT(bp.stats().runs, bp.partition().cells().size()) << "chunked";
    for (const auto& [name, scene] : adversarialScenes(70, 5))
      expectExactOnGrid(small, scene, 4, name + " capacity " + std::to_string(capacity));
  }
}

TEST(UniformGrid, BatchesAndThreadsGiveExactlyTheBruteForcePairs) {
  ModelBackend model(DeviceParams::seed(2, 6, 5));
  for (std::size_t n : {0u, 2u, 300u, 1000u})
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 3)) {
      const auto exact = bruteForce(boxes);
      std::vector<Pair> pairs;
      BroadPhase batched(model, {.cellSize = 16, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 7});
      batched.findPairs(boxes, pairs);
      EXPECT_EQ(sorted(pairs), exact) << name << " batched";
      BroadPhase threaded([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 6, 5)); },
                          {.cellSize = 16, .partition = PartitionKind::UniformGrid, .threads = 2, .cellsPerBatch = 5});
      threaded.findPairs(boxes, pairs);
      EXPECT_EQ(sorted(pairs), exact) << name << " 2 threads";
    }
}

TEST(UniformGrid, DegenerateScenesStayExactAndBounded) {
  CpuBackend cpu;
  // Every box at one point: no extent, one cell.
  const std::vector<Aabb> point(300, box(7, 7, 7, 7, 7, 7));
  BroadPhase bp(cpu, {.cellSize = 16, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 1});
  std::vector<Pair> pairs;
  bp.findPairs(point, pairs);
  EXPECT_FALSE(gridOf(bp).fellBack());
  EXPECT_EQ(gridOf(bp).resolution(), (std::array<std::uint32_t, 3>{1, 1, 1}));
  EXPECT_EQ(pairs.size(), 300u * 299u / 2u);

  // One huge box among small ones joins every cell, and is reported with each once.
  std::vector<Aabb> oneHuge = scatteredBoxes(2000, 5, -100, 100, 0.1f, 2);
  oneHuge.push_back(box(-1e30f, -1e30f, -1e30f, 1e30f, 1e30f, 1e30f));
  bp.findPairs(oneHuge, pairs);
  EXPECT_FALSE(gridOf(bp).fellBack());
  EXPECT_EQ(sorted(pairs), bruteForce(oneHuge));

  // Many huge boxes would join every cell each: the tree takes the frame.
  std::vector<Aabb> manyHuge = scatteredBoxes(2000, 6, -100, 100, 0.1f, 2);
  for (std::size_t i = 0; i < manyHuge.size(); i += 4) manyHuge[i] = box(-150, -150, -150, 150, 150, 150);
  bp.findPairs(manyHuge, pairs);
  EXPECT_TRUE(gridOf(bp).fellBack());
  EXPECT_EQ(sorted(pairs), bruteForce(manyHuge));
  EXPECT_LE(gridOf(bp).storedItems(), 3 * UniformGrid::kMaxEntriesPerBox * manyHuge.size());
  EXPECT_LE(gridOf(bp).storedBoxes(), UniformGrid::kMaxEntriesPerBox * manyHuge.size());
  EXPECT_FALSE(bp.partition().cellsOutliveBuild()) << "the tree's cells live during the call only";

  // A flat scene: one axis has almost no extent, and the cell count stays near the target.
  std::vector<Aabb> flat = scatteredBoxes(4000, 9, -100, 100, 0.1f, 1);
  for (auto& b : flat) b.min[2] = 0, b.max[2] = 1e-6f;
  BroadPhase flatPhase(cpu, {.cellSize = 16, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 1});
  flatPhase.findPairs(flat, pairs);
  const auto r = gridOf(flatPhase).resolution();
  EXPECT_EQ(r[2], 1u);
  EXPECT_LT(static_cast<double>(r[0]) * r[1] * r[2], 4.0 * 2 * 4000 / 16);
  EXPECT_EQ(sorted(pairs), bruteForce(flat));
}

TEST(UniformGrid, IsExactOnBoxesAtTheEndsOfTheKeyRange) {
  // Keys straight from the KeyBox API, NaN bit patterns included: 0 and 2^32-1
  // lie beyond the infinities' keys.
  const std::uint32_t top = ~0u;
  std::vector<KeyBox> keys = {{{0, 0, 0}, {0, 0, 0}},
                              {{0, 0, 0}, {top, top, top}},
                              {{top, top, top}, {top, top, top}},
                              {{0, top, 0}, {top, top, top}},
                              {{top - 1, 0, 5}, {top, 1, 6}}};
  std::mt19937 rng(3);
  for (int i = 0; i < 400; ++i) {
    KeyBox k;
    for (int a = 0; a < 3; ++a) {
      const std::uint32_t x = rng() % 4 == 0 ? (rng() % 2 ? top - rng() % 4 : rng() % 4) : rng();
      const std::uint32_t w = rng() % 3 == 0 ? rng() : rng() % 0x100000u;
      k.min[a] = x;
      k.max[a] = x + std::min(w, top - x);
    }
    keys.push_back(k);
  }
  CpuBackend cpu;
  ModelBackend small(DeviceParams::seed(2, 6, 5));
  for (Backend* backend : std::initializer_list<Backend*>{&cpu, &small})
    for (std::size_t cell : {1u, 4u, 32u}) {
      BroadPhase bp(*backend, {.cellSize = cell, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 1});
      std::vector<Pair> pairs;
      bp.findPairs(std::span<const KeyBox>(keys), pairs);
      EXPECT_EQ(sorted(pairs), bruteForceKeys(keys)) << backend->name() << " cell " << cell;
      if (!gridOf(bp).fellBack())
        expectCellsPartitionSpaceAndHoldExactlyTheirBoxes(bp.partition(), keys, "key-range ends");
    }
}

TEST(UniformGrid, BoxesExactlyOnEitherSideOfAPlaneJoinTheRightCells) {
  // The planes depend only on n, the cell size and the scene's bounds: boxes
  // replaced by ones at a plane's key and the key below it (the bounds kept)
  // meet the same planes. Each plane gets a point on either side and a box
  // from one to the other, whose pairs are reported where the rule says.
  const std::vector<Aabb> boxes = scatteredBoxes(600, 12, -50, 50, 0.5f, 3);
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  UniformGrid grid;
  grid.build(keys, 16, {});
  ASSERT_FALSE(grid.fellBack());
  const std::vector<Cell> before = grid.cells();
  std::array<std::vector<std::uint32_t>, 3> planes;
  for (const Cell& c : before)
    for (int a = 0; a < 3; ++a)
      if (c.lo[a] > 0) planes[a].push_back(static_cast<std::uint32_t>(c.lo[a]));
  for (auto& p : planes) {
    std::sort(p.begin(), p.end());
    p.erase(std::unique(p.begin(), p.end()), p.end());
    ASSERT_GE(p.size(), 2u);
  }
  std::array<std::uint32_t, 3> mid{};
  for (int a = 0; a < 3; ++a) mid[a] = floatToKey(0.0f);
  std::array<std::uint32_t, 3> keyLo{~0u, ~0u, ~0u}, keyHi{0, 0, 0};
  for (const KeyBox& k : keys)
    for (int a = 0; a < 3; ++a) keyLo[a] = std::min(keyLo[a], k.min[a]), keyHi[a] = std::max(keyHi[a], k.max[a]);
  std::vector<KeyBox> edited = keys;
  std::size_t slot = 0;
  const auto put = [&](const KeyBox& k) {
    // Never overwrite a box that holds the scene's bounds.
    for (bool bounds = true; bounds; ++slot) {
      bounds = false;
      for (int a = 0; a < 3; ++a)
        bounds = bounds || edited[slot].min[a] == keyLo[a] || edited[slot].max[a] == keyHi[a];
      if (!bounds) edited[slot] = k;
    }
  };
  for (int a = 0; a < 3; ++a)
    for (std::uint32_t p : planes[a]) {
      KeyBox below{mid, mid}, at{mid, mid}, across{mid, mid};
      below.min[a] = below.max[a] = p - 1;
      at.min[a] = at.max[a] = p;
      across.min[a] = p - 1;
      across.max[a] = p;
      put(below);
      put(at);
      put(across);
    }
  grid.build(edited, 16, {});
  ASSERT_FALSE(grid.fellBack());
  ASSERT_EQ(grid.cells().size(), before.size());
  for (std::size_t c = 0; c < before.size(); ++c) {
    EXPECT_EQ(grid.cells()[c].lo, before[c].lo);
    EXPECT_EQ(grid.cells()[c].hi, before[c].hi);
  }
  expectCellsPartitionSpaceAndHoldExactlyTheirBoxes(grid, edited, "boxes on the planes");
  CpuBackend cpu;
  BroadPhase bp(cpu, {.cellSize = 16, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 1});
  std::vector<Pair> pairs;
  bp.findPairs(std::span<const KeyBox>(edited), pairs);
  EXPECT_EQ(sorted(pairs), bruteForceKeys(edited));
}

TEST(Partition, KindsParseFromTheCliSpellingAndRejectOthers) {
  EXPECT_EQ(parsePartitionKind("kd"), PartitionKind::KdTree);
  EXPECT_EQ(parsePartitionKind("grid"), PartitionKind::UniformGrid);
  EXPECT_THROW(parsePartitionKind("octree"), std::invalid_argument);
  EXPECT_EQ(makePartition(PartitionKind::UniformGrid)->name(), "grid");
  EXPECT_EQ(makePartition(PartitionKind::KdTree)->name(), "k-d");
}

TEST(UniformGrid, BuildIndexOnTwoThreadsGivesTheCellsItemsAndBitsOfABuildOnOne) {
  ThreadPool pool(2);
  std::size_t gridded = 0;
  for (std::size_t n : {1, 2, 3, 300, 2000})
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 2))
      for (std::size_t cell : {2u, 16u, 64u}) {
        const std::vector<KeyBox> keys = keysOf(boxes);
        UniformGrid serial, parallel;
        serial.build(keys, cell, {});
        parallel.buildIndex(keys, cell, nullptr, &pool);
        const std::string label = name + " n=" + std::to_string(n) + " cell " + std::to_string(cell);
        ASSERT_EQ(parallel.fellBack(), serial.fellBack()) << label;
        ASSERT_EQ(parallel.cells().size(), serial.cells().size()) << label;
        for (std::size_t c = 0; c < serial.cells().size(); ++c) {
          const Cell &a = serial.cells()[c], &b = parallel.cells()[c];
          ASSERT_EQ(b.lo, a.lo) << label << " cell " << c;
          ASSERT_EQ(b.hi, a.hi) << label << " cell " << c;
          const auto ia = serial.items(a), ib = parallel.items(b);
          ASSERT_TRUE(std::equal(ia.begin(), ia.end(), ib.begin(), ib.end())) << label << " cell " << c;
          const auto ba = serial.below(a), bb = parallel.below(b);
          ASSERT_TRUE(std::equal(ba.begin(), ba.end(), bb.begin(), bb.end())) << label << " cell " << c;
        }
        if (parallel.fellBack()) continue;
        ++gridded;
        if (!serial.cells().empty()) EXPECT_TRUE(parallel.packed(parallel.cells().front()).empty()) << label;
      }
  EXPECT_GE(gridded, 30u) << "most scenes should be gridded, not handed to the tree";
}
