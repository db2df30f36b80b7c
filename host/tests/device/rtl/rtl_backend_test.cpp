#include <algorithm>
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <random>
#include <span>
#include <tuple>

#include <fmt/format.h>

#include "device/model_backend.hpp"
#include "device/cpu_backend.hpp"
#include "device/built_device.hpp"
#include "device/backend.hpp"
#include "bpaccel_params.h"
#include "broad_phase/broad_phase.hpp"
#include "partition/uniform_grid.hpp"
#include "core/keys.hpp"
#include "device/rtl/rtl_backend.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

// The keys the device compares: the host's, narrowed as one cell where the
// device's are narrower (BroadPhase narrows each cell the same way).
std::vector<KeyBox> deviceKeysOf(const std::vector<Aabb>& boxes) {
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  if constexpr (BPACCEL_KEY_WIDTH < 32) {
    std::vector<KeyBox> narrow(keys.size());
    narrowKeys(keys, BPACCEL_KEY_WIDTH, narrow);
    return narrow;
  }
  return keys;
}

// The pairs the device must report for `boxes`: by the definition, on the
// keys it compares (with 32-bit keys, the same as on the floats). Through a
// BroadPhase the tests below expect the floats' pairs at any key width.
std::vector<Pair> devicePairs(const std::vector<Aabb>& boxes) {
  if constexpr (BPACCEL_KEY_WIDTH == 32) return bruteForce(boxes);
  const auto keys = deviceKeysOf(boxes);
  std::vector<Pair> pairs;
  for (std::uint32_t i = 0; i < keys.size(); ++i)
    for (std::uint32_t j = i + 1; j < keys.size(); ++j)
      if (overlaps(keys[i], keys[j])) pairs.emplace_back(i, j);
  return pairs;
}

// One batch run on the hardware and on the model.
struct BothRuns {
  std::vector<Pair> fromRtl, fromModel;
  RunStats rtlStats, modelStats;
};

BothRuns runBoth(Backend& rtl, Backend& model, const std::vector<Aabb>& boxes) {
  const auto keys = deviceKeysOf(boxes);
  BothRuns r;
  rtl.run(keys, r.fromRtl, r.rtlStats);
  model.run(keys, r.fromModel, r.modelStats);
  return r;
}

// Run cycles of one cell of n boxes (a CELLS command of one cell) with a
// consumer that never stalls, from the header's closed form (independent of
// ModelBackend): the run, start to done, and the cycle that ends the cell.
std::uint64_t expectedRunCycles(std::uint64_t n) {
  if (n < 2) return 1;
  const std::uint64_t startup = BPACCEL_ARCH_STREAM ? BPACCEL_READ_LATENCY : 0;
  return startup + scheduleIssueCycles(n, BPACCEL_M) + BPACCEL_RUN_OVERHEAD_CYCLES + 1;
}

// One run of the hardware against the model and the brute-force reference.
void expectSameRun(const std::string& label, const std::vector<Aabb>& boxes, const BothRuns& r) {
  const auto& [fromRtl, fromModel, rtlStats, modelStats] = r;
  const std::size_t n = boxes.size();
  EXPECT_EQ(fromRtl, fromModel) << label;  // same pairs, in the same order
  EXPECT_EQ(sorted(fromRtl), devicePairs(boxes)) << label;
  EXPECT_EQ(rtlStats.loadCycles, modelStats.loadCycles) << label;
  EXPECT_EQ(rtlStats.loadCycles, n + 2) << label;  // the count, one box a cycle, then the start
  EXPECT_EQ(rtlStats.cycles, modelStats.cycles) << label;
  EXPECT_EQ(rtlStats.beatsReceived, modelStats.beatsReceived) << label;
  EXPECT_EQ(rtlStats.issueCycles, scheduleIssueCycles(n, BPACCEL_M)) << label;
  EXPECT_EQ(rtlStats.cycles, expectedRunCycles(n)) << label;
  EXPECT_EQ(rtlStats.stallCycles, 0u) << label;
}

// A consumer that takes no beat while `stuck`, with timeouts short enough
// (in simulated time; the model's core runs at 250 MHz) that a hang costs little.
RtlBackendConfig stuckConsumer(const bool& stuck) {
  return {.shell = {.replyReady = [&stuck](std::uint64_t) { return !stuck; }},
          .driver = {.timeoutFloor = std::chrono::microseconds{20}, .slowestCoreMHz = 50,
                     .abortTimeout = std::chrono::microseconds{10}, .readyTimeout = std::chrono::microseconds{10}}};
}

}  // namespace

TEST(RtlBackend, ReportsTheArchitectureItWasBuiltWith) {
  EXPECT_EQ(RtlBackend::architecture(), BPACCEL_ARCH_STREAM ? "stream" : "seed");
  EXPECT_NO_THROW(RtlBackend{});  // the driver's probe checks the shell's registers against the headers
}

TEST(RtlBackend, AgreesWithTheModelOnPairsCyclesAndBeats) {
  RtlBackend rtl;
  ModelBackend model(builtDeviceParams());
  std::mt19937 rng(42);
  std::vector<std::size_t> sizes = {0, 1, 2, 3, BPACCEL_M - 1, BPACCEL_M, BPACCEL_M + 1, 2 * BPACCEL_M + 1,
                                    BPACCEL_CAPACITY};
  for (int t = 0; t < 12; ++t) sizes.push_back(rng() % 400);
  for (std::size_t n : sizes)
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n))) {
      expectSameRun(name + " n=" + std::to_string(n), boxes, runBoth(rtl, model, boxes));
      if (n > 400) break;  // the full-capacity case runs one scene only
    }
}

TEST(RtlBackend, TheComparisonCatchesAWrongPairAndAWrongCount) {
  // The same comparison as above must fail when one pair or one count is off.
  RtlBackend rtl;
  ModelBackend model(builtDeviceParams());
  const auto boxes = adversarialScenes(40, 3).at(1).second;  // clusters: many hits
  const BothRuns runs = runBoth(rtl, model, boxes);
  ASSERT_FALSE(runs.fromRtl.empty());
  expectSameRun("untampered", boxes, runs);
  // Failures reported while `body` runs, caught rather than failing this test.
  const auto failuresOf = [](auto body) {
    ::testing::TestPartResultArray failures;
    {
      ::testing::ScopedFakeTestPartResultReporter catcher(
          ::testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &failures);
      body();
    }
    return failures.size();
  };
  auto wrongPair = runs;
  wrongPair.fromRtl.back().second ^= 1u;
  EXPECT_GE(failuresOf([&] { expectSameRun("tampered pair", boxes, wrongPair); }), 1);
  auto wrongLoads = runs;
  wrongLoads.rtlStats.loadCycles += 1;
  EXPECT_GE(failuresOf([&] { expectSameRun("tampered loads", boxes, wrongLoads); }), 1);
}

TEST(RtlBackend, StallingConsumerLosesNoPairAndCountsTheStalls) {
  std::mt19937 pattern(5);
  RtlBackend rtl([&](std::uint64_t) { return pattern() % 4 == 0; });
  ModelBackend model(builtDeviceParams());
  std::uint64_t stalls = 0;
  for (const auto& [name, boxes] : adversarialScenes(300, 77)) {
    const auto [fromRtl, fromModel, rtlStats, modelStats] = runBoth(rtl, model, boxes);
    EXPECT_EQ(fromRtl, fromModel) << name;
    stalls += rtlStats.stallCycles;
    EXPECT_EQ(rtlStats.cycles, rtlStats.stallCycles + expectedRunCycles(300)) << name;
    EXPECT_EQ(rtlStats.issueCycles, scheduleIssueCycles(300, BPACCEL_M)) << name;
    EXPECT_EQ(rtlStats.loadCycles, modelStats.loadCycles) << name;
  }
  EXPECT_GT(stalls, 0u);  // the consumer really held the hardware back (sparse scenes have too few beats to)
}

TEST(RtlBackend, RecoversAfterAHungRunAndRunsTheNextBatchExactly) {
  bool consumerStuck = true;  // a consumer that never takes a beat hangs the run
  RtlBackend rtl(stuckConsumer(consumerStuck));
  ModelBackend model(builtDeviceParams());
  const auto dense = adversarialScenes(60, 9).at(1).second;  // clusters: a hit the consumer never takes
  std::vector<Pair> pairs;
  RunStats stats;
  EXPECT_THROW(rtl.run(deviceKeysOf(dense), pairs, stats), std::runtime_error);
  EXPECT_TRUE(pairs.empty());  // no partial answer is left behind
  EXPECT_EQ(stats.runs, 0u);
  consumerStuck = false;
  for (const auto& [name, boxes] : adversarialScenes(50, 10))
    expectSameRun("after the hang: " + name, boxes, runBoth(rtl, model, boxes));
}

TEST(RtlBackend, IsExactThroughTheKdTreeAndAcrossChunks) {
  RtlBackend rtl;
  for (const auto& [name, boxes] : adversarialScenes(500, 8))
    for (std::optional<std::size_t> cell : {std::optional<std::size_t>{}, std::optional<std::size_t>{16}}) {
      BroadPhase bp(rtl, {.cellSize = cell});
      std::vector<Pair> pairs;
      bp.findPairs(boxes, pairs);
      EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << name;
    }
  // More boxes than the hardware holds, all in one unsplittable cell.
  std::vector<Aabb> many;
  for (std::size_t i = 0; i < BPACCEL_CAPACITY + BPACCEL_CAPACITY / 3; ++i)
    many.push_back(i % 7 == 0 ? box(0, 0, 0, 10, 10, 10) : box(1, 1, 1, 2, 2, 2));
  BroadPhase bp(rtl, {.cellSize = std::nullopt});
  std::vector<Pair> pairs;
  bp.findPairs(many, pairs);
  EXPECT_EQ(pairs.size(), many.size() * (many.size() - 1) / 2);
  EXPECT_EQ(sorted(pairs), bruteForce(many));
  // Three chunks of capacity/2: with bipartite runs, each chunk alone and the
  // pairs (0,1), (0,2), (1,2) across; else runs (0,1), (0,2), (1,2) of both chunks.
  EXPECT_EQ(bp.stats().runs, BPACCEL_BIPARTITE_RUNS ? 6u : 3u);
}

TEST(RtlBackend, BipartiteRunsAgreeWithTheModelAndTestOnlyAcrossTheSplit) {
  RtlBackend rtl;
  ModelBackend model(builtDeviceParams());
  ASSERT_EQ(rtl.bipartite(), BPACCEL_BIPARTITE_RUNS != 0);
  ASSERT_EQ(model.bipartite(), rtl.bipartite());
  const auto keys = deviceKeysOf(adversarialScenes(3 * BPACCEL_M + 5, 21).at(1).second);  // clusters: many hits
  std::vector<Pair> pairs;
  RunStats stats;
  if (!rtl.bipartite()) {
    EXPECT_THROW(rtl.runBipartite(keys, 3, pairs, stats), std::logic_error);
    EXPECT_THROW(model.runBipartite(keys, 3, pairs, stats), std::logic_error);
    return;
  }
  EXPECT_THROW(rtl.runBipartite(keys, 0, pairs, stats), std::invalid_argument);
  EXPECT_THROW(rtl.runBipartite(keys, keys.size(), pairs, stats), std::invalid_argument);
  EXPECT_TRUE(pairs.empty());
  std::mt19937 rng(8);
  std::vector<std::size_t> sizes = {2, 3, BPACCEL_M + 1, BPACCEL_M + 2, 2 * BPACCEL_M + 3, 5 * BPACCEL_M + 1};
  for (int t = 0; t < 4; ++t) sizes.push_back(2 + rng() % 300);
  for (std::size_t n : sizes)
    for (std::size_t split : {std::size_t{1}, n / 2, n - 1, std::size_t{1 + rng() % (n - 1)}, std::min<std::size_t>(n - 1, 2 * BPACCEL_M + 1)}) {
      if (split < 1 || split >= n) continue;
      const auto boxes = adversarialScenes(n, static_cast<unsigned>(n + split)).at(1).second;
      const auto label = fmt::format("n={} split={}", n, split);
      const auto k = deviceKeysOf(boxes);
      BothRuns r;
      rtl.runBipartite(k, split, r.fromRtl, r.rtlStats);
      model.runBipartite(k, split, r.fromModel, r.modelStats);
      EXPECT_EQ(r.fromRtl, r.fromModel) << label;  // same pairs, in the same order
      std::vector<Pair> across;
      for (const Pair& p : devicePairs(boxes))
        if (p.first < split && p.second >= split) across.push_back(p);
      EXPECT_EQ(sorted(r.fromRtl), across) << label;
      EXPECT_EQ(r.rtlStats.issueCycles, scheduleIssueCycles(n, BPACCEL_M, split)) << label;
      EXPECT_EQ(r.rtlStats.cycles, r.modelStats.cycles) << label;
      EXPECT_EQ(r.rtlStats.loadCycles, r.modelStats.loadCycles) << label;
      EXPECT_EQ(r.rtlStats.beatsReceived, r.modelStats.beatsReceived) << label;
      EXPECT_EQ(r.rtlStats.cycles, BPACCEL_READ_LATENCY + r.rtlStats.issueCycles + BPACCEL_RUN_OVERHEAD_CYCLES + 1)
          << label;
    }
}

TEST(RtlBackend, IsExactThroughTheUniformGridAndAcrossChunks) {
  RtlBackend rtl;
  for (const auto& [name, boxes] : adversarialScenes(500, 8)) {
    BroadPhase bp(rtl, {.cellSize = 16, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 1});
    std::vector<Pair> pairs;
    bp.findPairs(boxes, pairs);
    EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << name;
  }
  // A cluster beyond the hardware's capacity inside one grid cell, among boxes
  // spread over the scene: the grid keeps it (no fallback) and it is chunked.
  std::vector<Aabb> clustered = scatteredBoxes(200, 4, 0, 100, 0.5f, 2);
  for (std::size_t i = 0; i < BPACCEL_CAPACITY + 100; ++i) clustered.push_back(box(1, 1, 1, 2, 2, 2));
  BroadPhase bp(rtl, {.cellSize = 256, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 1});
  std::vector<Pair> pairs;
  bp.findPairs(clustered, pairs);
  EXPECT_FALSE(dynamic_cast<const UniformGrid&>(bp.partition()).fellBack());
  std::size_t largest = 0;
  for (const auto& cell : bp.partition().cells()) largest = std::max<std::size_t>(largest, cell.count);
  EXPECT_GT(largest, BPACCEL_CAPACITY);
  EXPECT_EQ(sorted(pairs), bruteForce(clustered));
}

TEST(RtlBackend, RejectsABatchAboveTheCapacity) {
  RtlBackend rtl;
  std::vector<KeyBox> keys(BPACCEL_CAPACITY + 1, KeyBox{{0, 0, 0}, {1, 1, 1}});
  std::vector<Pair> pairs;
  RunStats stats;
  EXPECT_THROW(rtl.run(keys, pairs, stats), std::length_error);
}

namespace {

// A batch of cells in float boxes and keys, and the spans a Backend takes.
struct Batch {
  std::vector<std::vector<Aabb>> boxes;
  std::vector<std::vector<KeyBox>> keys;
  std::vector<std::span<const KeyBox>> spans;
};

// Cells whose sizes hit the edges (0, 1, 2, m, m+1, the capacity) or are
// random, each one of the adversarial scenes (touching, identical, ...).
Batch randomBatch(std::size_t cells, unsigned seed, bool withFullCell) {
  std::mt19937 rng(seed);
  const std::vector<std::size_t> edges = {0, 1, 2, BPACCEL_M, BPACCEL_M + 1};
  Batch b;
  for (std::size_t k = 0; k < cells; ++k) {
    std::size_t n = rng() % 3 == 0 ? rng() % 120 : edges[rng() % edges.size()];
    if (withFullCell && k == cells / 2) n = BPACCEL_CAPACITY;
    auto scenes = adversarialScenes(n, static_cast<unsigned>(rng()));
    b.boxes.push_back(std::move(scenes.at(rng() % scenes.size()).second));
  }
  for (const auto& c : b.boxes) b.keys.push_back(deviceKeysOf(c));
  for (const auto& c : b.keys) b.spans.emplace_back(c);
  return b;
}

struct BatchResult {
  std::vector<Pair> pairs;
  std::vector<std::size_t> cellEnds;
  RunStats stats;
};

BatchResult runBatchOn(Backend& backend, const Batch& b) {
  BatchResult r;
  backend.runBatch(b.spans, r.pairs, r.cellEnds, r.stats);
  return r;
}

// The pairs of cell k of a batch result.
std::vector<Pair> cellPairs(const BatchResult& r, std::size_t k) {
  const std::size_t begin = k == 0 ? 0 : r.cellEnds.at(k - 1);
  return {r.pairs.begin() + static_cast<std::ptrdiff_t>(begin), r.pairs.begin() + static_cast<std::ptrdiff_t>(r.cellEnds.at(k))};
}

std::uint64_t hardwareBatches(std::size_t cells) { return (cells + BPACCEL_BATCH_CELLS - 1) / BPACCEL_BATCH_CELLS; }

}  // namespace

TEST(RtlBatch, AgreesWithTheModelAndWithTheCellsRunOneByOne) {
  RtlBackend rtl;
  ModelBackend model(builtDeviceParams());
  // Few cells, one at the capacity, and more cells than one hardware batch holds.
  for (const auto& [cells, seed, full] : {std::tuple{5u, 1u, false}, std::tuple{9u, 2u, true},
                                          std::tuple{BPACCEL_BATCH_CELLS + 7u, 3u, false}}) {
    const Batch b = randomBatch(cells, seed, full);
    const std::string label = fmt::format("{} cells, seed {}", cells, seed);
    const BatchResult fromRtl = runBatchOn(rtl, b);
    const BatchResult fromModel = runBatchOn(model, b);
    EXPECT_EQ(fromRtl.pairs, fromModel.pairs) << label;
    EXPECT_EQ(fromRtl.cellEnds, fromModel.cellEnds) << label;
    ASSERT_EQ(fromRtl.cellEnds.size(), cells) << label;
    const RunStats& r = fromRtl.stats;
    const RunStats& m = fromModel.stats;
    EXPECT_EQ(r.runs, cells) << label;
    EXPECT_EQ(r.batches, hardwareBatches(cells)) << label;
    EXPECT_EQ(m.batches, r.batches) << label;
    EXPECT_EQ(r.loadCycles, m.loadCycles) << label;
    EXPECT_EQ(r.cycles, m.cycles) << label;
    EXPECT_EQ(r.issueCycles, m.issueCycles) << label;
    EXPECT_EQ(r.beatsReceived, m.beatsReceived) << label;
    EXPECT_EQ(r.hits, fromRtl.pairs.size()) << label;
    EXPECT_EQ(r.stallCycles, 0u) << label;
    // Cell by cell: the same pairs, in the same order, as single runs (each a
    // command of one cell); the batch's runs cost their cycles; its loads, a
    // count and a start per hardware batch instead of per cell, less what runs hid.
    RunStats singles;
    for (std::size_t k = 0; k < cells; ++k) {
      std::vector<Pair> one;
      rtl.run(b.spans[k], one, singles);
      EXPECT_EQ(cellPairs(fromRtl, k), one) << label << " cell " << k;
      EXPECT_EQ(sorted(one), devicePairs(b.boxes[k])) << label << " cell " << k;
    }
    if (BPACCEL_BATCH_OVERLAPS_LOADS)
      EXPECT_LT(r.loadCycles, singles.loadCycles - cells + r.batches) << label;
    else
      EXPECT_EQ(r.loadCycles, singles.loadCycles - cells + r.batches) << label;
    EXPECT_EQ(r.cycles, singles.cycles) << label;
    EXPECT_EQ(r.hits, singles.hits) << label;
    EXPECT_EQ(singles.batches, cells) << label;
    if (cells > BPACCEL_BATCH_CELLS) {
      // The counter comparison can fail: a model that splits into other hardware batches disagrees.
      DeviceParams wrong = builtDeviceParams();
      wrong.batchCells = BPACCEL_BATCH_CELLS > 1 ? 1 : 2;
      ModelBackend wrongSplit(wrong);
      EXPECT_NE(runBatchOn(wrongSplit, b).stats.loadCycles, r.loadCycles) << label;
    }
    // And a model that gets the overlap wrong disagrees too.
    DeviceParams wrong = builtDeviceParams();
    wrong.batchOverlapsLoads = !wrong.batchOverlapsLoads;
    ModelBackend wrongOverlap(wrong);
    EXPECT_NE(runBatchOn(wrongOverlap, b).stats.loadCycles, r.loadCycles) << label;
  }
}

TEST(RtlBatch, BipartiteCellsInABatchAgreeWithTheModelAndWithTheirSingleRuns) {
  RtlBackend rtl;
  ModelBackend model(builtDeviceParams());
  const Batch b = randomBatch(BPACCEL_BATCH_CELLS + 5, 9, true);
  // About half the cells of two or more objects bipartite, at a random split.
  std::mt19937 rng(10);
  std::vector<std::size_t> splits;
  for (const auto& cell : b.spans)
    splits.push_back(cell.size() >= 2 && rng() % 2 ? 1 + rng() % (cell.size() - 1) : 0);
  ASSERT_GT(std::count_if(splits.begin(), splits.end(), [](std::size_t s) { return s != 0; }), 10);
  BatchResult fromRtl;
  if (!rtl.bipartite()) {
    // The seed's device refuses a split: nothing reaches it.
    EXPECT_THROW(rtl.runBatch(b.spans, splits, fromRtl.pairs, fromRtl.cellEnds, fromRtl.stats), std::logic_error);
    EXPECT_THROW(model.runBatch(b.spans, splits, fromRtl.pairs, fromRtl.cellEnds, fromRtl.stats), std::logic_error);
    EXPECT_EQ(fromRtl.stats.runs, 0u);
    return;
  }
  rtl.runBatch(b.spans, splits, fromRtl.pairs, fromRtl.cellEnds, fromRtl.stats);
  BatchResult fromModel;
  model.runBatch(b.spans, splits, fromModel.pairs, fromModel.cellEnds, fromModel.stats);
  EXPECT_EQ(fromRtl.pairs, fromModel.pairs);
  EXPECT_EQ(fromRtl.cellEnds, fromModel.cellEnds);
  const RunStats& r = fromRtl.stats;
  const RunStats& m = fromModel.stats;
  EXPECT_EQ(r.runs, b.spans.size());
  EXPECT_EQ(r.batches, hardwareBatches(b.spans.size()));
  EXPECT_EQ(r.loadCycles, m.loadCycles);
  EXPECT_EQ(r.cycles, m.cycles);
  EXPECT_EQ(r.issueCycles, m.issueCycles);
  EXPECT_EQ(r.beatsReceived, m.beatsReceived);
  // Cell by cell: what the cell's single run gives (bipartite or not), the
  // same cycles, and loads the runs hide.
  RunStats singles;
  for (std::size_t k = 0; k < b.spans.size(); ++k) {
    std::vector<Pair> one;
    if (splits[k] == 0)
      rtl.run(b.spans[k], one, singles);
    else
      rtl.runBipartite(b.spans[k], splits[k], one, singles);
    EXPECT_EQ(cellPairs(fromRtl, k), one) << "cell " << k;
    std::vector<Pair> expected;
    for (const Pair& p : devicePairs(b.boxes[k]))
      if (splits[k] == 0 || (p.first < splits[k] && p.second >= splits[k])) expected.push_back(p);
    EXPECT_EQ(sorted(one), expected) << "cell " << k << " split " << splits[k];
  }
  EXPECT_EQ(r.issueCycles, singles.issueCycles);
  EXPECT_EQ(r.cycles, singles.cycles);
  EXPECT_LT(r.loadCycles, singles.loadCycles - b.spans.size() + r.batches);
}

TEST(RtlBatch, RefusesBadSplitsNamingTheCellBeforeTouchingTheDevice) {
  RtlBackend rtl;
  ModelBackend model(builtDeviceParams());
  const Batch b = randomBatch(4, 11, false);
  const std::vector<std::size_t> tooFew = {0, 0};
  std::vector<std::size_t> atN(b.spans.size(), 0);
  atN.back() = b.spans.back().size();  // a split must lie below n
  for (Backend* backend : {static_cast<Backend*>(&rtl), static_cast<Backend*>(&model)}) {
    BatchResult r;
    EXPECT_THROW(backend->runBatch(b.spans, tooFew, r.pairs, r.cellEnds, r.stats), std::invalid_argument);
    if (backend->bipartite()) {
      try {
        backend->runBatch(b.spans, atN, r.pairs, r.cellEnds, r.stats);
        ADD_FAILURE() << backend->name() << " took a split of n";
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("cell 3"), std::string::npos) << e.what();
      }
    }
    EXPECT_TRUE(r.pairs.empty());
    EXPECT_TRUE(r.cellEnds.empty());
    EXPECT_EQ(r.stats.runs, 0u);
  }
  // And the device is still fine.
  EXPECT_EQ(runBatchOn(rtl, b).pairs, runBatchOn(model, b).pairs);
}

TEST(RtlBatch, StallingConsumerLosesNoPairAndCountsTheStalls) {
  std::mt19937 pattern(6);
  RtlBackend rtl([&](std::uint64_t) { return pattern() % 3 == 0; });
  ModelBackend model(builtDeviceParams());
  const Batch b = randomBatch(BPACCEL_BATCH_CELLS + 2, 4, false);
  const BatchResult fromRtl = runBatchOn(rtl, b);
  const BatchResult fromModel = runBatchOn(model, b);
  EXPECT_EQ(fromRtl.pairs, fromModel.pairs);
  EXPECT_EQ(fromRtl.cellEnds, fromModel.cellEnds);
  EXPECT_GT(fromRtl.stats.stallCycles, 0u);
  EXPECT_EQ(fromRtl.stats.cycles, fromModel.stats.cycles + fromRtl.stats.stallCycles);
  // Stalls lengthen runs, which can only hide more of the loads.
  if (BPACCEL_BATCH_OVERLAPS_LOADS)
    EXPECT_LE(fromRtl.stats.loadCycles, fromModel.stats.loadCycles);
  else
    EXPECT_EQ(fromRtl.stats.loadCycles, fromModel.stats.loadCycles);
}

TEST(RtlBatch, TheDefaultRunsEachCellAsItsOwnBatch) {
  CpuBackend cpu;
  ModelBackend model(builtDeviceParams());
  const Batch b = randomBatch(12, 5, false);
  const BatchResult fromCpu = runBatchOn(cpu, b);
  const BatchResult fromModel = runBatchOn(model, b);
  ASSERT_EQ(fromCpu.cellEnds.size(), 12u);
  for (std::size_t k = 0; k < 12; ++k)
    EXPECT_EQ(sorted(cellPairs(fromCpu, k)), sorted(cellPairs(fromModel, k))) << "cell " << k;
  EXPECT_EQ(fromCpu.stats.runs, 12u);
  EXPECT_EQ(fromCpu.stats.batches, 12u);
}

TEST(RtlBatch, RejectsACellAboveTheCapacityBeforeTouchingTheDevice) {
  RtlBackend rtl;
  std::vector<KeyBox> small(3, KeyBox{{0, 0, 0}, {1, 1, 1}});
  std::vector<KeyBox> big(BPACCEL_CAPACITY + 1, KeyBox{{0, 0, 0}, {1, 1, 1}});
  const std::vector<std::span<const KeyBox>> cells = {small, big};
  std::vector<Pair> pairs;
  std::vector<std::size_t> ends;
  RunStats stats;
  EXPECT_THROW(rtl.runBatch(cells, pairs, ends, stats), std::length_error);
  EXPECT_TRUE(pairs.empty());
  EXPECT_TRUE(ends.empty());
  EXPECT_EQ(stats.runs, 0u);
}

TEST(RtlBatch, RecoversAfterAHungBatchAndRunsTheNextExactly) {
  bool consumerStuck = true;  // a consumer that never takes a beat hangs the batch
  RtlBackend rtl(stuckConsumer(consumerStuck));
  ModelBackend model(builtDeviceParams());
  const Batch b = randomBatch(4, 7, false);
  ASSERT_FALSE(runBatchOn(model, b).pairs.empty());  // a beat the consumer never takes
  std::vector<Pair> pairs = {{0, 1}};  // what the caller had before stays
  std::vector<std::size_t> ends = {1};
  RunStats stats;
  EXPECT_THROW(rtl.runBatch(b.spans, pairs, ends, stats), std::runtime_error);
  EXPECT_EQ(pairs.size(), 1u);
  EXPECT_EQ(ends.size(), 1u);
  EXPECT_EQ(stats.runs, 0u);
  EXPECT_EQ(stats.batches, 0u);
  consumerStuck = false;
  const BatchResult fromRtl = runBatchOn(rtl, b);
  EXPECT_EQ(fromRtl.pairs, runBatchOn(model, b).pairs);
}

TEST(RtlBatch, RunsOnItsOwnThreadBehindAnAsyncBackendWithTheSameResults) {
  RtlBackend direct;
  const auto boxes = scatteredBoxes(3 * BPACCEL_M + 40, 31, 0.0f, 20.0f, 0.5f, 3.0f);
  std::vector<Pair> expected, pairs;
  BroadPhase sync(direct, {.cellSize = 2 * BPACCEL_M, .cellsPerBatch = 3});
  sync.findPairs(boxes, expected);
  {
    // The Verilated model is built, run and destroyed on the hand-overs' own thread.
    BroadPhase async([] { return std::make_unique<RtlBackend>(); },
                     {.cellSize = 2 * BPACCEL_M, .cellsPerBatch = 3, .handOvers = HandOvers::Asynchronous});
    async.findPairs(boxes, pairs);
    EXPECT_EQ(pairs, expected);
    EXPECT_EQ(async.stats().deviceCycles(), sync.stats().deviceCycles());
    EXPECT_EQ(async.stats().beatsReceived, sync.stats().beatsReceived);
  }
  EXPECT_EQ(sorted(pairs), bruteForce(boxes));
}
