#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

#include "bpaccel_params.h"
#include "broad_phase/broad_phase.hpp"
#include "core/keys.hpp"
#include "device/backend.hpp"
#include "device/built_device.hpp"
#include "device/cpu_backend.hpp"
#include "device/model_backend.hpp"
#include "scenes/exact_pairs.hpp"
#include "partition/kd_tree.hpp"
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

TEST(BroadPhase, SeveralThreadsGiveExactlyTheSinglePairs) {
  for (std::size_t threads : {2u, 3u}) {
    BroadPhase cpu([] { return std::make_unique<CpuBackend>(); }, {.cellSize = 8, .threads = threads});
    // A small capacity: cells above it are chunked inside the workers.
    BroadPhase model([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 6, 5)); },
                     {.cellSize = 16, .threads = threads});
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

TEST(BroadPhase, RejectsSettingsItCannotRunWith) {
  const auto cpu = [] { return std::make_unique<CpuBackend>(); };
  // One cell per batch leaves asynchronous hand-overs nothing to overlap.
  EXPECT_THROW(BroadPhase(cpu, {.cellSize = 8, .handOvers = HandOvers::Asynchronous}), std::invalid_argument);
  EXPECT_THROW(BroadPhase(cpu, {.cellSize = 0}), std::invalid_argument);
  EXPECT_THROW(BroadPhase(cpu, {.cellsPerBatch = 0}), std::invalid_argument);
  CpuBackend one;  // a single backend serves one synchronous thread only
  EXPECT_THROW(BroadPhase(one, {.threads = 2}), std::invalid_argument);
  EXPECT_THROW(BroadPhase(one, {.cellsPerBatch = 2, .handOvers = HandOvers::Polled}), std::invalid_argument);
  EXPECT_NO_THROW(BroadPhase(one, {.cellSize = 1, .cellsPerBatch = 1}));
}

TEST(BroadPhaseConfig, CellSizesParseFromTheCliSpellingAndPrintBack) {
  EXPECT_EQ(parseCellSize("none"), std::nullopt);
  EXPECT_EQ(parseCellSize("64"), std::optional<std::size_t>{64});
  for (const char* bad : {"0", "-3", "64x", "", "sixty"}) EXPECT_THROW(parseCellSize(bad), std::invalid_argument) << bad;
  EXPECT_EQ(cellSizeName(std::nullopt), "none");
  EXPECT_EQ(cellSizeName(128), "128");
  EXPECT_EQ((BroadPhaseConfig{.cellsPerBatch = 64, .firstBatchCells = 4}.firstBatch()), 4u);
  EXPECT_EQ((BroadPhaseConfig{.cellsPerBatch = 8, .firstBatchCells = 0}.firstBatch()), 8u);
  EXPECT_EQ((BroadPhaseConfig{.cellsPerBatch = 8, .firstBatchCells = 20}.firstBatch()), 8u);
}

TEST(BroadPhase, RejectsZeroThreadsAndAnEmptyFactory) {
  EXPECT_THROW(BroadPhase([] { return std::make_unique<CpuBackend>(); }, {.cellSize = 8, .threads = 0}), std::invalid_argument);
  EXPECT_THROW(BroadPhase([] { return std::unique_ptr<Backend>(); }, {.cellSize = 8, .threads = 2}), std::invalid_argument);
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
    for (std::size_t n : {0u, 2u, 300u, 500u})
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
  BroadPhase model([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 6, 5)); },
                   {.cellSize = 16, .threads = 2, .cellsPerBatch = 5});
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

}  // namespace

TEST(BroadPhase, AsynchronousAndPolledHandOversGiveTheSynchronousPairsCountersAndRecords) {
  for (const HandOvers handOvers : {HandOvers::Asynchronous, HandOvers::Polled})
  for (const PartitionKind partition : {PartitionKind::KdTree, PartitionKind::UniformGrid})
    for (std::size_t perBatch : {2u, 5u, 64u})
      for (std::size_t n : {0u, 2u, 300u, 500u})
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
    BroadPhase bp([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 6, 5)); },
                  {.cellSize = 16, .threads = 2, .cellsPerBatch = 5, .handOvers = handOvers});
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
      BroadPhase bp([failAt] { return std::make_unique<FailingModel>(failAt); },
                    {.cellSize = 8, .cellsPerBatch = 4, .handOvers = handOvers});
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
                BroadPhase bp(make,
                              {.cellSize = cell, .partition = partition, .cellsPerBatch = perBatch, .handOvers = handOvers});
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


TEST(BroadPhase, TheCpuBackendRunsItsCellsOnTheHostExactlyForEveryPartitionCellSizeAndThreadCount) {
  std::vector<std::unique_ptr<BroadPhase>> phases;
  std::vector<std::string> labels;
  for (std::size_t threads : {1u, 2u})
    for (PartitionKind kind : {PartitionKind::KdTree, PartitionKind::UniformGrid, PartitionKind::Automatic})
      for (CellSize cell : {CellSize(std::nullopt), CellSize(1), CellSize(8), CellSize(200), CellSize::automatic()}) {
        phases.push_back(std::make_unique<BroadPhase>([] { return std::make_unique<CpuBackend>(); },
                                                      BroadPhaseConfig{.cellSize = cell, .partition = kind, .threads = threads}));
        EXPECT_EQ(phases.back()->threads(), threads);
        labels.push_back(fmt::format("{} cell {} threads {}", partitionName(kind), cell.name(), threads));
      }
  for (std::size_t n : {0u, 1u, 97u, 400u})
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 21)) {
      const auto exact = bruteForce(boxes);
      for (std::size_t k = 0; k < phases.size(); ++k) {
        std::vector<Pair> pairs{{1, 2}};  // cleared first
        phases[k]->findPairs(boxes, pairs);
        EXPECT_EQ(sorted(pairs), exact) << name << " n=" << n << " " << labels[k];
        EXPECT_EQ(phases[k]->stats().hits, pairs.size()) << labels[k];
      }
    }
}

TEST(BroadPhase, TheAutomaticChoiceIsOneCellForSmallScenesAndAPartitionAbove) {
  const auto cpu = [] { return std::make_unique<CpuBackend>(); };
  const auto small = scatteredBoxes(AutomaticChoice::kOneCellUpTo, 1, 0, 10, 0.5f, 2);
  const auto large = scatteredBoxes(AutomaticChoice::kOneCellUpTo + 1, 1, 0, 10, 0.5f, 2);
  std::vector<Pair> pairs;
  BroadPhase automatic(cpu, {});
  automatic.findPairs(small, pairs);
  EXPECT_EQ(automatic.choice(), (CellChoice{PartitionKind::UniformGrid, std::nullopt}));
  automatic.findPairs(large, pairs);
  EXPECT_EQ(automatic.choice(), (CellChoice{PartitionKind::UniformGrid, AutomaticChoice::kFirstCellSize}));
  // A partition named: only the cell size is chosen, for every scene size.
  BroadPhase tree(cpu, {.partition = PartitionKind::KdTree});
  tree.findPairs(small, pairs);
  EXPECT_EQ(tree.choice(), (CellChoice{PartitionKind::KdTree, AutomaticChoice::kFirstCellSize}));
  // A cell size given alone means the k-d tree, as it always has.
  BroadPhase sized(cpu, {.cellSize = 32});
  sized.findPairs(large, pairs);
  EXPECT_EQ(sized.choice(), (CellChoice{PartitionKind::KdTree, 32}));
  EXPECT_EQ(choiceName(sized.choice()), "k-d 32");
  EXPECT_EQ(choiceName(automatic.choice()), "grid 64");
  EXPECT_EQ(choiceName({PartitionKind::UniformGrid, std::nullopt}), "one cell");
}

TEST(BroadPhase, TheAutomaticChoiceIsExactOnADevice) {
  ModelBackend model(DeviceParams::seed(2, 6, 5));
  BroadPhase bp(model, {});
  for (std::size_t n : {50u, 700u})
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 2)) {
      std::vector<Pair> pairs;
      bp.findPairs(boxes, pairs);
      EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << name << " n=" << n << " " << choiceName(bp.choice());
    }
}

TEST(BroadPhaseConfig, CellSizeIsAutomaticByDefaultAndParsesPartitionAuto) {
  EXPECT_TRUE(BroadPhaseConfig{}.cellSize.isAutomatic());
  EXPECT_EQ(BroadPhaseConfig{}.partition, PartitionKind::Automatic);
  EXPECT_THROW(CellSize::automatic().fixed(), std::logic_error);
  EXPECT_EQ(CellSize(64).fixed(), std::optional<std::size_t>{64});
  EXPECT_EQ(CellSize(std::nullopt).name(), "none");
  EXPECT_EQ(CellSize::automatic().name(), "auto");
  EXPECT_EQ(parsePartitionKind("auto"), PartitionKind::Automatic);
  EXPECT_THROW(parsePartitionKind("octree"), std::invalid_argument);
}
