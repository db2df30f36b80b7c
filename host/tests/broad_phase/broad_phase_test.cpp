#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <algorithm>
#include <chrono>
#include <functional>
#include <set>
#include <stdexcept>

#include "device/model_backend.hpp"
#include "device/cpu_backend.hpp"
#include "device/built_device.hpp"
#include "core/all_pairs_kernel.hpp"
#include "device/async_backend.hpp"
#include "model/timeline.hpp"
#include "device/backend.hpp"
#include "broad_phase/broad_phase.hpp"
#include "bpaccel_params.h"
#include "exact_pairs.hpp"
#include "partition/kd_tree.hpp"
#include "core/keys.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

const std::vector<std::optional<std::size_t>> kCellSizes = {std::nullopt, 1, 2, 3, 5, 8, 16, 32, 64, 256};

void expectExact(Backend& backend, const std::vector<Aabb>& boxes, std::optional<std::size_t> cell,
                 const std::string& what) {
  BroadPhase bp(backend, {.cellSize = cell});
  std::vector<Pair> pairs;
  bp.findPairs(boxes, pairs);
  const std::string label = what + " backend " + backend.name() + " cell " + (cell ? std::to_string(*cell) : "none");
  // Exactly once: the sorted list equals the reference, which has no repeats.
  EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << label;
}

}  // namespace

TEST(BroadPhase, ModelAndCpuAreExactOnAdversarialScenesForEveryCellSize) {
  ModelBackend model(builtDeviceParams());
  CpuBackend cpu;
  for (std::size_t n : {0u, 1u, 2u, 7u, 150u, 600u})
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 11))
      for (const auto& cell : kCellSizes) {
        expectExact(model, boxes, cell, name + " n=" + std::to_string(n));
        expectExact(cpu, boxes, cell, name + " n=" + std::to_string(n));
      }
}

TEST(BroadPhase, CoversCellsAboveTheCapacityInChunksExactly) {
  // A tiny capacity forces chunking of cells the tree cannot split and of whole scenes.
  // The seed's model chunks into triangular chunk-pair runs, the stream's into bipartite ones.
  for (std::size_t capacity : {2u, 4u, 6u, 16u})
    for (std::uint64_t streamReadLatency : {0u, 4u}) {
      ModelBackend small(streamReadLatency ? DeviceParams::stream(2, capacity, 5, streamReadLatency)
                                         : DeviceParams::seed(2, capacity, 5));
      for (const auto& [name, boxes] : adversarialScenes(70, 5))
        for (const auto& cell : {std::optional<std::size_t>{}, std::optional<std::size_t>{4},
                                 std::optional<std::size_t>{40}})
          expectExact(small, boxes, cell,
                      name + " capacity " + std::to_string(capacity) + (streamReadLatency ? " stream" : " seed"));
    }
}

TEST(BroadPhase, CellsAboveTheCapacityRunAsBipartiteChunkPairsTestingEachPairOnce) {
  // 300 identical boxes: one leaf, ten chunks of 32 (the last 12).
  const std::vector<Aabb> same(300, box(1, 1, 1, 2, 2, 2));
  const std::size_t m = 4, capacity = 64, chunk = 32, k = 10;
  std::vector<std::size_t> sizes;
  for (std::size_t first = 0; first < same.size(); first += chunk) sizes.push_back(std::min(chunk, same.size() - first));
  ASSERT_EQ(sizes.size(), k);
  std::uint64_t bipartiteIssue = 0, triangularIssue = 0;
  for (std::size_t p = 0; p < k; ++p) {
    bipartiteIssue += scheduleIssueCycles(sizes[p], m);
    for (std::size_t q = p + 1; q < k; ++q) {
      bipartiteIssue += scheduleIssueCycles(sizes[p] + sizes[q], m, sizes[p]);
      triangularIssue += scheduleIssueCycles(sizes[p] + sizes[q], m);
    }
  }
  ModelBackend stream(DeviceParams::stream(m, capacity, 3, 4, true)), seed(DeviceParams::seed(m, capacity, 3));
  for (Backend* backend : {static_cast<Backend*>(&stream), static_cast<Backend*>(&seed)}) {
    BroadPhase bp(*backend, {.cellSize = 16});
    std::vector<Pair> pairs;
    bp.findPairs(same, pairs);
    EXPECT_EQ(pairs.size(), 300u * 299u / 2u);
    EXPECT_EQ(sorted(pairs), bruteForce(same));
    if (backend->bipartite()) {
      EXPECT_EQ(bp.stats().runs, k + k * (k - 1) / 2);  // each chunk alone, each two across
      EXPECT_EQ(bp.stats().issueCycles, bipartiteIssue);
    } else {
      EXPECT_EQ(bp.stats().runs, k * (k - 1) / 2);  // each two chunks together
      EXPECT_EQ(bp.stats().issueCycles, triangularIssue);
    }
  }
  EXPECT_LT(bipartiteIssue, triangularIssue * 7 / 10);  // small chunks: the 2m - 1 prefix per block weighs more
  // Asynchronous hand-overs run the bipartite runs in the same order with the same cycles.
  LastFrameTiming syncTiming, asyncTiming;
  BroadPhase sync(stream, {.cellSize = 16, .cellsPerBatch = 5, .observer = &syncTiming});
  BroadPhase async([&] { return std::make_unique<ModelBackend>(DeviceParams::stream(m, capacity, 3, 4, true)); },
                   {.cellSize = 16, .cellsPerBatch = 5, .handOvers = HandOvers::Asynchronous, .observer = &asyncTiming});
  std::vector<Pair> expected, pairs;
  sync.findPairs(same, expected);
  async.findPairs(same, pairs);
  EXPECT_EQ(pairs, expected);
  EXPECT_EQ(async.stats().deviceCycles(), sync.stats().deviceCycles());
  EXPECT_EQ(asyncTiming.handOvers().size(), syncTiming.handOvers().size());
  // The bipartite runs share hand-overs with the chunks (5 cells a batch), so
  // loads hide behind runs: fewer load cycles than the runs one by one.
  EXPECT_EQ(sync.stats().batches, (k + k * (k - 1) / 2 + 4) / 5);
  BroadPhase oneByOne(stream, {.cellSize = 16, .cellsPerBatch = 1});
  oneByOne.findPairs(same, pairs);
  EXPECT_EQ(oneByOne.stats().batches, k + k * (k - 1) / 2);
  EXPECT_EQ(oneByOne.stats().issueCycles, sync.stats().issueCycles);
  EXPECT_LT(sync.stats().loadCycles, oneByOne.stats().loadCycles / 2);
}

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
    EXPECT_EQ(stats.cycles, 4 + stats.issueCycles + 3) << "split " << split;
  }
}

TEST(BroadPhase, DegenerateScenesFallBackToChunkedLeaves) {
  // All boxes identical: no plane splits them, so one leaf holds all 300.
  std::vector<Aabb> same(300, box(1, 1, 1, 2, 2, 2));
  ModelBackend small(DeviceParams::seed(4, 64, 5));
  BroadPhase bp(small, {.cellSize = 16});
  std::vector<Pair> pairs;
  bp.findPairs(same, pairs);
  EXPECT_EQ(bp.partition().cells().size(), 1u);
  EXPECT_EQ(pairs.size(), 300u * 299u / 2u);
  EXPECT_EQ(sorted(pairs), bruteForce(same));
  EXPECT_GT(bp.stats().runs, 1u);  // chunked
}

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

TEST(BroadPhase, RejectsBadInputNamingTheObject) {
  CpuBackend cpu;
  BroadPhase bp(cpu, {.cellSize = 16});
  std::vector<Aabb> boxes = {box(0, 0, 0, 1, 1, 1), box(0, 0, 0, 1, 1, 1), box(3, 0, 0, 1, 1, 1)};
  std::vector<Pair> pairs;
  EXPECT_THROW(
      {
        try {
          bp.findPairs(boxes, pairs);
        } catch (const InputError& e) {
          EXPECT_EQ(e.object(), 2u);
          throw;
        }
      },
      InputError);
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

TEST(AllPairsKernel, SimdGivesTheScalarPairsInTheSameOrderForEverySize) {
  const AllPairsKernel simd, scalar = AllPairsKernel::scalar();
  AllPairsKernel::Scratch scratch;
  std::vector<std::size_t> sizes;
  for (std::size_t n = 0; n <= 40; ++n) sizes.push_back(n);  // every remainder modulo the vector width
  sizes.push_back(257);
  for (std::size_t n : sizes)
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 3)) {
      std::vector<KeyBox> keys;
      toKeys(boxes, keys);
      std::vector<Pair> fromSimd, fromScalar;
      simd.run(keys, fromSimd, scratch);
      scalar.run(keys, fromScalar, scratch);
      const std::string label = name + " n=" + std::to_string(n) + " isa " + std::string(simd.isa());
      EXPECT_EQ(fromSimd, fromScalar) << label;
      EXPECT_EQ(fromScalar, bruteForce(boxes)) << label;  // i then j order is the brute force's order
    }
}

TEST(AllPairsKernel, BoxesOverEveryKeyPairOnlyWithBoxesNotWithThePadding) {
  // Keys 0 and 2^32-1 are the padding's own values: a box over all of key
  // space overlaps the padding lanes, which must never become pairs.
  const std::uint32_t top = ~0u;
  const AllPairsKernel simd;
  AllPairsKernel::Scratch scratch;
  for (std::size_t n = 1; n <= 19; ++n) {
    std::vector<KeyBox> keys(n, KeyBox{{0, 0, 0}, {top, top, top}});
    std::vector<Pair> pairs, all;
    simd.run(keys, pairs, scratch);
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t j = i + 1; j < n; ++j) all.emplace_back(i, j);
    EXPECT_EQ(pairs, all) << "n=" << n << " isa " << simd.isa();
  }
}

TEST(BroadPhase, SeveralThreadsGiveExactlyTheSinglePairs) {
  for (std::size_t threads : {2u, 3u}) {
    BroadPhase cpu([] { return std::make_unique<CpuBackend>(); }, {.cellSize = 8, .threads = threads});
    // A small capacity: cells above it are chunked inside the workers.
    BroadPhase model([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 6, 5)); }, {.cellSize = 16, .threads = threads});
    EXPECT_EQ(cpu.threads(), threads);
    for (std::size_t n : {0u, 2u, 300u, 1000u})
      for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 7)) {
        const auto exact = bruteForce(boxes);
        std::vector<Pair> pairs;
        cpu.findPairs(boxes, pairs);
        EXPECT_EQ(sorted(pairs), exact) << name << " cpu threads " << threads;
        model.findPairs(boxes, pairs);
        EXPECT_EQ(sorted(pairs), exact) << name << " model threads " << threads;
      }
  }
}

TEST(BroadPhase, RejectsZeroThreadsAndAnEmptyFactory) {
  EXPECT_THROW(BroadPhase([] { return std::make_unique<CpuBackend>(); }, {.cellSize = 8, .threads = 0}), std::invalid_argument);
  EXPECT_THROW(BroadPhase([] { return std::unique_ptr<Backend>(); }, {.cellSize = 8, .threads = 2}), std::invalid_argument);
}

TEST(ModelPipeline, OverlapsHostLinkAndDeviceAsWorkedOutByHand) {
  // 1 us a cycle, one box (24 bytes) a microsecond on the link, one beat a microsecond.
  PipelineModel model{1e6, 24e6, 0, 24, 24};
  HandOverRecord first, second;
  first.readySeconds = 10e-6;
  first.decodeSeconds = 2e-6;
  first.stats.boxesSent = 4;
  first.stats.loadCycles = 5;  // the port, not the link, bounds the load: 5 us
  first.stats.cycles = 20;
  first.stats.beatsReceived = 3;
  second.readySeconds = 12e-6;  // measured after the first run's 2 us decode: ready at 10 us without it
  second.decodeSeconds = 1e-6;
  second.stats.boxesSent = 2;
  second.stats.loadCycles = 3;
  second.stats.cycles = 10;
  const double host = 15e-6;
  auto t = modelPipeline({first, second}, host, model);
  // First: device 10..35 us, decoded 35..37. Second waits for the device: 35..48, decoded 48..49.
  EXPECT_NEAR(t.producerSeconds, 12e-6, 1e-12);
  EXPECT_NEAR(t.device[0].start, 10e-6, 1e-12);
  EXPECT_NEAR(t.device[0].end, 35e-6, 1e-12);
  EXPECT_NEAR(t.device[1].start, 35e-6, 1e-12);
  EXPECT_NEAR(t.decode[1].end, 49e-6, 1e-12);
  EXPECT_NEAR(t.frameSeconds, 49e-6, 1e-12);
  // A latency each way: the first starts at 11 and completes at 37; the second starts at 36.
  model.link.latencySeconds = 1e-6;
  t = modelPipeline({first, second}, host, model);
  EXPECT_NEAR(t.decode[0].start, 37e-6, 1e-12);
  EXPECT_NEAR(t.device[1].start, 36e-6, 1e-12);
  EXPECT_NEAR(t.frameSeconds, 51e-6, 1e-12);
}

TEST(ModelPipeline, HoldsTheProducerBackWhileItsBatchesInFlightAreUndecoded) {
  // The hand-worked case above, with room for one batch only: the second is
  // ready at 10 us but its batch is free once the first is decoded, at 37.
  PipelineModel model{1e6, 24e6, 0, 24, 24};
  EXPECT_EQ(model.batchesInFlight, kBatchesInFlight);  // the host's own bound by default
  model.batchesInFlight = 1;
  HandOverRecord first, second;
  first.readySeconds = 10e-6;
  first.decodeSeconds = 2e-6;
  first.stats.boxesSent = 4;
  first.stats.loadCycles = 5;
  first.stats.cycles = 20;
  first.stats.beatsReceived = 3;
  second.readySeconds = 12e-6;
  second.decodeSeconds = 1e-6;
  second.stats.boxesSent = 2;
  second.stats.loadCycles = 3;
  second.stats.cycles = 10;
  const auto t = modelPipeline({first, second}, 15e-6, model);
  EXPECT_NEAR(t.decode[0].end, 37e-6, 1e-12);
  EXPECT_NEAR(t.device[1].start, 37e-6, 1e-12);  // not 35, when the device was free
  EXPECT_NEAR(t.decode[1].end, 51e-6, 1e-12);
  // The producer's 27 us wait moves the rest of its work too: 15 - 3 of decoding + 27.
  EXPECT_NEAR(t.producerSeconds, 39e-6, 1e-12);
  EXPECT_NEAR(t.frameSeconds, 51e-6, 1e-12);
  // Two in flight: no wait, the worked case's 49 us.
  model.batchesInFlight = 2;
  EXPECT_NEAR(modelPipeline({first, second}, 15e-6, model).frameSeconds, 49e-6, 1e-12);
  model.batchesInFlight = 0;
  EXPECT_THROW(modelPipeline({first, second}, 15e-6, model), std::invalid_argument);
}

TEST(ModelPipeline, PolledDecodesOnTheProducerBetweenHandOversAsWorkedOutByHand) {
  // 1 us a cycle, one box a microsecond on the link, one beat a microsecond, no latency.
  PipelineModel model{1e6, 24e6, 0, 24, 24};
  std::vector<HandOverRecord> runs(3);
  runs[0].readySeconds = 10e-6;
  runs[0].decodeSeconds = 2e-6;
  runs[0].stats.boxesSent = 4;
  runs[0].stats.loadCycles = 5;
  runs[0].stats.cycles = 1;
  runs[0].stats.beatsReceived = 3;  // on the link 15..18: arrives at 18
  runs[1].readySeconds = 22e-6;     // the serial run's clock: 20 us of own work and the first decode
  runs[1].decodeSeconds = 1e-6;
  runs[1].stats.boxesSent = runs[1].stats.loadCycles = 1;
  runs[2].readySeconds = 24e-6;  // 21 us of own work
  runs[2].decodeSeconds = 1e-6;
  runs[2].stats.boxesSent = runs[2].stats.loadCycles = runs[2].stats.cycles = 1;
  const double host = 28e-6;  // 3 us of own work after the last hand-over
  // A decoder thread: the third is handed over at 21, runs 21..23, decoded 23..24; the producer ends at 24.
  EXPECT_NEAR(modelPipeline(runs, host, model).frameSeconds, 24e-6, 1e-12);
  // The producer decoding: the second goes at 20 (device 20..21); then it
  // decodes the first (20..22) and the second (22..23), both arrived; it
  // hands the third over at 24 (device 24..26), works until 27, decodes 27..28.
  model.decodeOnProducer = true;
  const auto t = modelPipeline(runs, host, model);
  ASSERT_EQ(t.decode.size(), 3u);
  EXPECT_NEAR(t.decode[0].start, 20e-6, 1e-12);
  EXPECT_NEAR(t.decode[1].start, 22e-6, 1e-12);
  EXPECT_NEAR(t.decode[1].end, 23e-6, 1e-12);
  EXPECT_NEAR(t.device[2].start, 24e-6, 1e-12);
  EXPECT_NEAR(t.producerSeconds, 27e-6, 1e-12);
  EXPECT_NEAR(t.frameSeconds, 28e-6, 1e-12);
  // With one batch in flight it waits for each answer before the next hand-over:
  // the first decoded 20..22, the second handed over at 22 (device 22..23), decoded 23..24 at the third's hand-over.
  model.batchesInFlight = 1;
  const auto one = modelPipeline(runs, host, model);
  EXPECT_NEAR(one.device[1].start, 22e-6, 1e-12);
  EXPECT_NEAR(one.decode[1].start, 23e-6, 1e-12);
  EXPECT_NEAR(one.device[2].start, 24e-6, 1e-12);
  EXPECT_NEAR(one.frameSeconds, 28e-6, 1e-12);
}

TEST(ModelPipeline, NeverBeatsTheBusiestLaneNorLosesToTheSerialSum) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> us(0, 5e-6);
  PipelineModel model{100e6, 4e9, 1e-6, 24, 4};
  for (int trial = 0; trial < 400; ++trial) {
    model.batchesInFlight = 1 + trial % 4;  // however few batches the host may have out
    model.decodeOnProducer = trial % 8 >= 4;  // and whichever thread decodes
    std::vector<HandOverRecord> runs(1 + rng() % 30);
    double ready = 0, host = 0, device = 0, serial = 0;
    for (auto& r : runs) {
      ready += us(rng);
      r.readySeconds = ready + host;  // the serial run's clock includes earlier decodes
      r.decodeSeconds = us(rng);
      host += r.decodeSeconds;
      r.stats.boxesSent = rng() % 300;
      r.stats.loadCycles = r.stats.boxesSent + 1;
      r.stats.cycles = rng() % 5000;
      r.stats.beatsReceived = rng() % 100;
      const double load = std::max(24.0 * r.stats.boxesSent / 4e9, r.stats.loadCycles / 100e6);
      device += load + r.stats.cycles / 100e6;
      serial += 2e-6 + load + r.stats.cycles / 100e6 + 4.0 * r.stats.beatsReceived / 4e9;
    }
    host += ready + us(rng);
    const auto t = modelPipeline(runs, host, model);
    EXPECT_GE(t.frameSeconds + 1e-15, device);
    EXPECT_GE(t.frameSeconds + 1e-15, t.producerSeconds);
    EXPECT_LE(t.frameSeconds, host + serial + 1e-12);
  }
}

TEST(BroadPhase, TellsItsObserverEveryHandOverInOrderWithItsOwnCounters) {
  ModelBackend small(DeviceParams::seed(4, 64, 5));
  LastFrameTiming timing;
  BroadPhase bp(small, {.cellSize = 16, .observer = &timing});
  std::vector<Pair> pairs;
  const auto boxes = adversarialScenes(500, 21).front().second;
  bp.findPairs(boxes, pairs);
  ASSERT_EQ(timing.handOvers().size(), bp.stats().runs);
  RunStats sum;
  double last = 0;
  for (const auto& r : timing.handOvers()) {
    sum += r.stats;
    EXPECT_GE(r.readySeconds, last);
    EXPECT_GE(r.decodeSeconds, 0);
    last = r.readySeconds;
  }
  EXPECT_EQ(sum.cycles, bp.stats().cycles);
  EXPECT_EQ(sum.loadCycles, bp.stats().loadCycles);
  EXPECT_EQ(sum.boxesSent, bp.stats().boxesSent);
  EXPECT_LE(last, timing.times().totalSeconds);
  EXPECT_GT(timing.times().totalSeconds, 0);
  // Without an observer nothing is timed; the pairs and counters are the same.
  BroadPhase untimed(small, {.cellSize = 16});
  std::vector<Pair> again;
  untimed.findPairs(boxes, again);
  EXPECT_EQ(again, pairs);
  EXPECT_EQ(untimed.stats().deviceCycles(), bp.stats().deviceCycles());
}

namespace {

// Wraps a backend and records, at each run, how many leaves the tree had made.
class LeafCountingBackend final : public Backend {
 public:
  LeafCountingBackend(Backend& inner, const BroadPhase*& phase) : inner_(inner), phase_(phase) {}
  std::string name() const override { return inner_.name(); }
  std::size_t capacity() const override { return inner_.capacity(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override {
    leavesAtRun.push_back(phase_->partition().cells().size());
    inner_.run(boxes, out, stats);
  }
  std::vector<std::size_t> leavesAtRun;

 private:
  Backend& inner_;
  const BroadPhase*& phase_;
};

}  // namespace

TEST(BroadPhase, CellsReachTheBackendWhileTheTreeIsStillBeingBuilt) {
  ModelBackend model(DeviceParams::seed(4, 64, 5));
  const BroadPhase* phase = nullptr;
  LeafCountingBackend counting(model, phase);
  BroadPhase bp(counting, {.cellSize = 16});
  phase = &bp;
  const std::vector<Aabb> boxes = scatteredBoxes(2000, 9, -40, 40, 0, 2);
  std::vector<Pair> pairs;
  bp.findPairs(boxes, pairs);
  const std::size_t leaves = bp.partition().cells().size();
  ASSERT_GT(leaves, 50u);
  ASSERT_FALSE(counting.leavesAtRun.empty());
  // The first cell runs when the tree has made one leaf, not all of them; and
  // the runs follow the leaves as they are made.
  EXPECT_EQ(counting.leavesAtRun.front(), 1u);
  EXPECT_TRUE(std::is_sorted(counting.leavesAtRun.begin(), counting.leavesAtRun.end()));
  EXPECT_EQ(sorted(pairs), bruteForce(boxes));
  // The streamed frame is the same as processing the finished tree's leaves in order.
  ModelBackend again(DeviceParams::seed(4, 64, 5));
  RunStats sum;
  std::vector<Pair> scratch;
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  for (const auto& leaf : bp.partition().cells()) {
    std::vector<KeyBox> cell;
    for (auto i : bp.partition().items(leaf)) cell.push_back(keys[i]);
    if (cell.size() >= 2) again.run(cell, scratch, sum);
  }
  EXPECT_EQ(sum.cycles, bp.stats().cycles);
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

TEST(BroadPhase, ScenesLargerThanTheCarryThresholdAreExactOnOneAndTwoThreads) {
  // Above KdTree::kCarryAbove the tree carries boxes and hands cells over packed.
  const std::size_t n = KdTree::kCarryAbove + 1000;
  const float edge = std::cbrt(static_cast<float>(n) / 0.05f);
  const std::vector<Aabb> boxes = scatteredBoxes(n, 5, 0, edge, 0.5f, 2);
  std::vector<Pair> exact, pairs;
  exactPairs(boxes, exact);
  CpuBackend cpu;
  BroadPhase one(cpu, {.cellSize = 64});
  one.findPairs(boxes, pairs);
  EXPECT_EQ(sorted(pairs), exact);
  BroadPhase two([] { return std::make_unique<CpuBackend>(); }, {.cellSize = 64, .threads = 2});
  two.findPairs(boxes, pairs);
  EXPECT_EQ(sorted(pairs), exact);
}

TEST(BroadPhase, BatchesOfCellsGiveExactlyThePairsOfSingleRunsWithTheSameCycles) {
  // A small capacity, so that chunk pairs of oversized cells travel in batches too.
  for (std::size_t capacity : {6u, 64u}) {
    ModelBackend model(DeviceParams::seed(2, capacity, 5));
    for (std::size_t n : {0u, 2u, 300u, 1000u})
      for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 3))
        for (const auto& cell : {std::optional<std::size_t>{}, std::optional<std::size_t>{4},
                                 std::optional<std::size_t>{16}}) {
          const std::string label = name + " capacity " + std::to_string(capacity) + " cell " +
                                    (cell ? std::to_string(*cell) : "none");
          BroadPhase single(model, {.cellSize = cell, .cellsPerBatch = 1});
          std::vector<Pair> expected;
          single.findPairs(boxes, expected);
          EXPECT_EQ(sorted(expected), bruteForce(boxes)) << label;
          EXPECT_EQ(single.stats().batches, single.stats().runs) << label;
          // 1000 is more than the model's hardware batch (64 cells): it splits the hand-over.
          for (std::size_t perBatch : {2u, 7u, 64u, 1000u}) {
            LastFrameTiming timing;
            BroadPhase batched(model, {.cellSize = cell, .cellsPerBatch = perBatch, .observer = &timing});
            std::vector<Pair> pairs;
            batched.findPairs(boxes, pairs);
            EXPECT_EQ(sorted(pairs), sorted(expected)) << label << " per batch " << perBatch;
            const RunStats& s = batched.stats();
            EXPECT_EQ(s.runs, single.stats().runs) << label;
            const std::size_t handOver = std::min<std::size_t>(perBatch, 64);
            if (perBatch <= 64)
              EXPECT_EQ(s.batches, (s.runs + handOver - 1) / handOver) << label << " per batch " << perBatch;
            else
              EXPECT_GE(s.batches, (s.runs + handOver - 1) / handOver) << label << " per batch " << perBatch;
            EXPECT_EQ(timing.handOvers().size(), (s.runs + perBatch - 1) / perBatch) << label;
            // The same cells on the same device: the same pair tests and loads.
            EXPECT_EQ(s.issueCycles, single.stats().issueCycles) << label;
            EXPECT_EQ(s.boxesSent, single.stats().boxesSent) << label;
            EXPECT_EQ(s.hits, single.stats().hits) << label;
          }
        }
  }
}

namespace {

// Wraps a backend and records each hand-over's cells (copies of their boxes) as they reach it.
class BatchRecordingBackend final : public Backend {
 public:
  explicit BatchRecordingBackend(Backend& inner) : inner_(inner) {}
  std::string name() const override { return inner_.name(); }
  std::size_t capacity() const override { return inner_.capacity(); }
  bool bipartite() const override { return inner_.bipartite(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override {
    batches.push_back({{boxes.begin(), boxes.end()}});
    inner_.run(boxes, out, stats);
  }
  using Backend::runBatch;
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override {
    auto& copies = batches.emplace_back();
    for (const auto& cell : cells) copies.emplace_back(cell.begin(), cell.end());
    inner_.runBatch(cells, splits, out, cellEnds, stats);
  }
  std::vector<std::vector<std::vector<KeyBox>>> batches;

 private:
  Backend& inner_;
};

}  // namespace

TEST(BroadPhase, BatchesReachTheDeviceInAscendingCellSizeSoThatTheirLoadsHide) {
  // The stream's model: each cell loads while the one before runs.
  ModelBackend stream(DeviceParams::stream(8, 256, 3, 4, true));
  const std::vector<Aabb> boxes = scatteredBoxes(3000, 21, -40, 40, 0, 3);
  for (const PartitionKind partition : {PartitionKind::UniformGrid, PartitionKind::KdTree})
    for (const std::size_t perBatch : {7u, 64u}) {
      const std::string label = std::string(partitionName(partition)) + " per batch " + std::to_string(perBatch);
      BatchRecordingBackend recording(stream);
      BroadPhase bp(recording, {.cellSize = 32, .partition = partition, .cellsPerBatch = perBatch});
      std::vector<Pair> pairs;
      bp.findPairs(boxes, pairs);
      EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << label;
      ASSERT_GT(recording.batches.size(), 2u) << label;
      bool someBatchWasOutOfOrder = false;
      RunStats ascending, descending;
      for (std::size_t b = 0; b < recording.batches.size(); ++b) {
        std::vector<std::size_t> sizes;
        for (const auto& cell : recording.batches[b]) sizes.push_back(cell.size());
        EXPECT_TRUE(std::is_sorted(sizes.begin(), sizes.end())) << label << " batch " << b;
        // The same cells largest first: each cell's loads now outlast the run before.
        std::vector<std::span<const KeyBox>> inOrder(recording.batches[b].begin(), recording.batches[b].end());
        std::vector<std::span<const KeyBox>> reversed(inOrder.rbegin(), inOrder.rend());
        std::vector<Pair> scratch;
        std::vector<std::size_t> ends;
        stream.runBatch(inOrder, scratch, ends, ascending);
        stream.runBatch(reversed, scratch, ends, descending);
        someBatchWasOutOfOrder = someBatchWasOutOfOrder || sizes.front() != sizes.back();
      }
      ASSERT_TRUE(someBatchWasOutOfOrder) << label << ": the scene must give cells of different sizes";
      EXPECT_EQ(ascending.loadCycles, bp.stats().loadCycles) << label;
      EXPECT_EQ(ascending.cycles, bp.stats().cycles) << label;
      EXPECT_LT(ascending.loadCycles, descending.loadCycles) << label;
      EXPECT_EQ(ascending.issueCycles, descending.issueCycles) << label;
    }
}

TEST(BroadPhase, SlowStartHandsOverFewCellsFirstThenTwiceAsManyEachTimeUpToTheBatch) {
  ModelBackend stream(DeviceParams::stream(8, 256, 3, 4, true));
  const std::vector<Aabb> boxes = scatteredBoxes(3000, 21, -40, 40, 0, 3);
  const std::vector<Pair> exact = bruteForce(boxes);
  for (const PartitionKind partition : {PartitionKind::UniformGrid, PartitionKind::KdTree})
    for (const auto& [first, perBatch] : std::vector<std::pair<std::size_t, std::size_t>>{{3, 40}, {1, 64}, {9, 7}}) {
      const std::string label = std::string(partitionName(partition)) + " first " + std::to_string(first) +
                                " per batch " + std::to_string(perBatch);
      BatchRecordingBackend recording(stream);
      LastFrameTiming timing;
      BroadPhase bp(recording, {.cellSize = 32,
                                .partition = partition,
                                .cellsPerBatch = perBatch,
                                .firstBatchCells = first,
                                .observer = &timing});
      EXPECT_EQ(bp.config().firstBatch(), std::min(first, perBatch)) << label;
      ModelBackend plainModel(DeviceParams::stream(8, 256, 3, 4, true));
      BroadPhase plain(plainModel, {.cellSize = 32, .partition = partition, .cellsPerBatch = perBatch});
      for (int frame = 0; frame < 2; ++frame) {  // each frame starts small again
        recording.batches.clear();
        std::vector<Pair> pairs, plainPairs;
        bp.findPairs(boxes, pairs);
        plain.findPairs(boxes, plainPairs);
        EXPECT_EQ(sorted(pairs), exact) << label;
        // Every cell still reaches the device once: the same runs and pair tests as full batches.
        EXPECT_EQ(bp.stats().runs, plain.stats().runs) << label;
        EXPECT_EQ(bp.stats().issueCycles, plain.stats().issueCycles) << label;
        ASSERT_GT(recording.batches.size(), 4u) << label;
        std::size_t expected = std::min(first, perBatch), cells = 0;
        for (std::size_t b = 0; b + 1 < recording.batches.size(); ++b) {  // the last holds what is left
          EXPECT_EQ(recording.batches[b].size(), expected) << label << " hand-over " << b;
          cells += recording.batches[b].size();
          expected = std::min(2 * expected, perBatch);
        }
        EXPECT_LE(recording.batches.back().size(), expected) << label;
        EXPECT_EQ(cells + recording.batches.back().size(), bp.stats().runs) << label;
        EXPECT_EQ(timing.handOvers().size(), recording.batches.size()) << label;
      }
    }
}

TEST(BroadPhase, BatchesWorkOnSeveralThreadsAndRejectZeroCellsPerBatch) {
  BroadPhase model([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 6, 5)); }, {.cellSize = 16, .threads = 2, .cellsPerBatch = 5});
  for (std::size_t n : {0u, 2u, 300u, 1000u})
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 9)) {
      std::vector<Pair> pairs;
      model.findPairs(boxes, pairs);
      EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << name;
      EXPECT_LE(model.stats().batches, model.stats().runs) << name;
    }
  ModelBackend m(DeviceParams::seed(2, 6, 5));
  EXPECT_THROW(BroadPhase(m, {.cellSize = 16, .cellsPerBatch = 0}), std::invalid_argument);
}

namespace {

// A model that fails its `failAt`-th batch (counted from 1 over its life), as a device that hangs would.
class FailingModel final : public Backend {
 public:
  explicit FailingModel(std::size_t failAt) : failAt_(failAt) {}
  std::string name() const override { return "failing model"; }
  std::size_t capacity() const override { return model_.capacity(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override {
    model_.run(boxes, out, stats);
  }
  using Backend::runBatch;
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override {
    if (++batches_ == failAt_) throw std::runtime_error("the device hung");
    model_.runBatch(cells, splits, out, cellEnds, stats);
  }

 private:
  ModelBackend model_{DeviceParams::seed(2, 16, 5)};
  std::size_t failAt_;
  std::size_t batches_ = 0;
};

std::vector<KeyBox> keysOf(const std::vector<Aabb>& boxes) {
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  return keys;
}

}  // namespace

TEST(AsyncBackend, GivesEachHandOverWhatTheBackendGivesInSubmissionOrder) {
  ModelBackend direct(DeviceParams::seed(2, 16, 5));
  AsyncBackend async([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 16, 5)); });
  EXPECT_EQ(async.name(), "model");
  EXPECT_EQ(async.capacity(), 16u);
  std::vector<std::vector<KeyBox>> scenes;
  for (unsigned seed = 0; seed < 6; ++seed) scenes.push_back(keysOf(scatteredBoxes(40, seed, 0.0f, 30.0f, 1.0f, 4.0f)));
  // Hand-overs of one to three cells of up to 16 boxes each, all submitted before any is waited for.
  std::vector<std::vector<std::span<const KeyBox>>> handOvers;
  for (std::size_t h = 0; h < scenes.size(); ++h) {
    std::vector<std::span<const KeyBox>> cells;
    for (std::size_t c = 0; c <= h % 3; ++c) cells.push_back(std::span<const KeyBox>(scenes[h]).subspan(8 * c, 16));
    handOvers.push_back(cells);
  }
  std::vector<std::future<BatchResult>> results;
  for (const auto& cells : handOvers) results.push_back(async.submit(cells));
  for (std::size_t h = 0; h < handOvers.size(); ++h) {
    // Polling: the result arrives without anyone waiting for it.
    while (results[h].wait_for(std::chrono::seconds(0)) != std::future_status::ready) std::this_thread::yield();
    const BatchResult got = results[h].get();
    BatchResult expected;
    direct.runBatch(handOvers[h], expected.pairs, expected.cellEnds, expected.stats);
    EXPECT_EQ(got.pairs, expected.pairs) << "hand-over " << h;
    EXPECT_EQ(got.cellEnds, expected.cellEnds) << "hand-over " << h;
    EXPECT_EQ(got.stats.deviceCycles(), expected.stats.deviceCycles()) << "hand-over " << h;
    EXPECT_EQ(got.stats.runs, expected.stats.runs) << "hand-over " << h;
    EXPECT_GT(got.stats.runs, 0u);
  }
}

TEST(AsyncBackend, PassesTheDevicesFailureToItsHandOverOnlyAndGoesOn) {
  AsyncBackend async([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 16, 5)); });
  const auto keys = keysOf(scatteredBoxes(20, 3, 0.0f, 10.0f, 1.0f, 4.0f));
  const std::vector<std::span<const KeyBox>> tooLarge = {std::span<const KeyBox>(keys)};  // 20 > capacity 16
  const std::vector<std::span<const KeyBox>> fits = {std::span<const KeyBox>(keys).first(16)};
  auto bad = async.submit(tooLarge);
  auto good = async.submit(fits);
  EXPECT_THROW(bad.get(), std::length_error);
  EXPECT_EQ(good.get().cellEnds.size(), 1u);
}

TEST(AsyncBackend, RethrowsAFailedDeviceConstructionFromItsOwnConstructor) {
  EXPECT_THROW(AsyncBackend([]() -> std::unique_ptr<Backend> { throw std::runtime_error("no device"); }),
               std::runtime_error);
  EXPECT_THROW(AsyncBackend([] { return std::unique_ptr<Backend>(); }), std::invalid_argument);
  EXPECT_THROW(BroadPhase([] { return std::make_unique<CpuBackend>(); }, {.cellSize = 8, .partition = PartitionKind::KdTree, .cellsPerBatch = 1, .handOvers = HandOvers::Asynchronous}),
               std::invalid_argument);  // one cell per batch: nothing to overlap
}

TEST(BroadPhase, AsynchronousAndPolledHandOversGiveTheSynchronousPairsCountersAndRecords) {
  for (const HandOvers handOvers : {HandOvers::Asynchronous, HandOvers::Polled})
  for (const PartitionKind partition : {PartitionKind::KdTree, PartitionKind::UniformGrid})
    for (std::size_t perBatch : {2u, 5u, 64u})
      for (std::size_t n : {0u, 2u, 300u, 1000u})
        for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 21)) {
          const std::string label = name + " n " + std::to_string(n) + " per batch " + std::to_string(perBatch) +
                                    (handOvers == HandOvers::Polled ? " polled" : " decoder thread");
          ModelBackend syncModel(DeviceParams::seed(2, 64, 5));
          // With 64 a batch, a slow start (hand-overs of 3, 6, 12, ...) on both.
          const std::size_t first = perBatch == 64 ? 3 : 0;
          LastFrameTiming syncTiming, asyncTiming;
          BroadPhase sync(syncModel, {.cellSize = 16,
                                      .partition = partition,
                                      .cellsPerBatch = perBatch,
                                      .firstBatchCells = first,
                                      .observer = &syncTiming});
          BroadPhase async([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 64, 5)); },
                           {.cellSize = 16,
                            .partition = partition,
                            .cellsPerBatch = perBatch,
                            .firstBatchCells = first,
                            .handOvers = handOvers,
                            .observer = &asyncTiming});
          EXPECT_EQ(async.config().handOvers, handOvers);
          for (int frame = 0; frame < 2; ++frame) {  // the second frame reuses the in-flight buffers
            std::vector<Pair> expected, pairs;
            sync.findPairs(boxes, expected);
            async.findPairs(boxes, pairs);
            EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << label;
            EXPECT_EQ(pairs, expected) << label;  // decoded in hand-over order, so in the same order
            EXPECT_EQ(async.stats().deviceCycles(), sync.stats().deviceCycles()) << label;
            EXPECT_EQ(async.stats().batches, sync.stats().batches) << label;
            const auto& syncRecords = syncTiming.handOvers();
            const auto& asyncRecords = asyncTiming.handOvers();
            ASSERT_EQ(asyncRecords.size(), syncRecords.size()) << label;
            for (std::size_t r = 0; r < syncRecords.size(); ++r)
              EXPECT_EQ(asyncRecords[r].stats.deviceCycles(), syncRecords[r].stats.deviceCycles()) << label;
          }
        }
}

TEST(BroadPhase, AsynchronousAndPolledHandOversWorkOnSeveralThreads) {
  for (const HandOvers handOvers : {HandOvers::Asynchronous, HandOvers::Polled}) {
    BroadPhase bp([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 6, 5)); }, {.cellSize = 16, .partition = PartitionKind::KdTree, .threads = 2, .cellsPerBatch = 5, .handOvers = handOvers});
    for (std::size_t n : {2u, 300u, 1000u})
      for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 23)) {
        std::vector<Pair> pairs;
        bp.findPairs(boxes, pairs);
        EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << name << (handOvers == HandOvers::Polled ? " polled" : "");
      }
  }
}

TEST(BroadPhase, AsynchronousAndPolledHandOversPassADeviceFailureOnAndRecover) {
  const auto boxes = scatteredBoxes(400, 5, 0.0f, 20.0f, 0.5f, 2.0f);
  for (const HandOvers handOvers : {HandOvers::Asynchronous, HandOvers::Polled})
    for (std::size_t failAt : {1u, 2u, 3u}) {
      const std::string label = "failing hand-over " + std::to_string(failAt) +
                                (handOvers == HandOvers::Polled ? " polled" : " decoder thread");
      BroadPhase bp([failAt] { return std::make_unique<FailingModel>(failAt); }, {.cellSize = 8, .partition = PartitionKind::KdTree, .cellsPerBatch = 4, .handOvers = handOvers});
      std::vector<Pair> pairs;
      EXPECT_THROW(bp.findPairs(boxes, pairs), std::runtime_error) << label;
      bp.findPairs(boxes, pairs);  // the device answers again: the next frame is whole
      EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << label;
    }
}

// A device that compares narrower keys than the host's gets each cell's keys
// narrowed (narrowKeys) and reports a superset of its pairs; the broad phase
// keeps only those whose full keys overlap. With fewer bits the device
// reports more: the check, not the device, makes it exact.
TEST(BroadPhase, NarrowKeyDevicesGiveExactlyTheFullKeyPairs) {
  const std::size_t m = 3, capacity = 24;
  std::map<unsigned, std::uint64_t> hits;  // device-reported pairs per key width, over every case
  for (const unsigned width : {1u, 4u, 16u, 32u}) {
    for (const bool stream : {true, false}) {  // the stream's model (bipartite chunk pairs) and the seed's
      const auto make = [&] {
        DeviceParams p = stream ? DeviceParams::stream(m, capacity, 3, 4, true) : DeviceParams::seed(m, capacity, 3);
        p.batchCells = 8;
        p.keyWidth = width;
        return std::make_unique<ModelBackend>(p);
      };
      for (std::size_t n : {2u, 150u, 400u})
        for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n)))
          for (const auto partition : {PartitionKind::KdTree, PartitionKind::UniformGrid})
            for (const auto& cell : {std::optional<std::size_t>{}, std::optional<std::size_t>{4},
                                     std::optional<std::size_t>{16}})
              for (const std::size_t perBatch : {1u, 8u}) {
                const auto handOvers = perBatch > 1 ? HandOvers::Asynchronous : HandOvers::Synchronous;
                BroadPhase bp(make, {.cellSize = cell, .partition = partition, .cellsPerBatch = perBatch, .handOvers = handOvers});
                std::vector<Pair> pairs;
                bp.findPairs(boxes, pairs);
                const std::string label = name + " n=" + std::to_string(n) + " width " + std::to_string(width) +
                                          " cell " + (cell ? std::to_string(*cell) : "none") + " per batch " +
                                          std::to_string(perBatch) + (stream ? " stream" : " seed");
                ASSERT_EQ(sorted(pairs), bruteForce(boxes)) << label;
                hits[width] += bp.stats().hits;
              }
    }
  }
  // Coarser keys, more candidates for the check to remove.
  EXPECT_GT(hits[1], hits[4]);
  EXPECT_GT(hits[4], hits[16]);
  EXPECT_GE(hits[16], hits[32]);
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
