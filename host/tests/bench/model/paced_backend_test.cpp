#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <stdexcept>
#include <vector>

#include "device/model_backend.hpp"
#include "device/backend.hpp"
#include "broad_phase/broad_phase.hpp"
#include "model/paced_backend.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using bpaccel::testing::adversarialScenes;
using bpaccel::testing::bruteForce;
using bpaccel::testing::sorted;

namespace {

std::vector<std::vector<KeyBox>> someCells() {
  std::vector<std::vector<KeyBox>> cells;
  for (std::size_t n : {5u, 9u, 3u}) {
    std::vector<KeyBox> cell;
    for (std::size_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::uint32_t>(4 * i);
      cell.push_back(KeyBox{{k, k, k}, {k + 6, k + 6, k + 6}});
    }
    cells.push_back(cell);
  }
  return cells;
}

std::vector<std::span<const KeyBox>> spansOf(const std::vector<std::vector<KeyBox>>& cells) {
  return {cells.begin(), cells.end()};
}

}  // namespace

TEST(RecordingBackend, GivesTheInnerBackendsAnswerAndRecordsEachHandOversOwn) {
  AnswerRecording recording;
  RecordingBackend recorder(std::make_unique<ModelBackend>(DeviceParams::seed(2, 64, 5)), recording);
  ModelBackend plain(DeviceParams::seed(2, 64, 5));
  const auto cells = someCells();
  std::vector<Pair> got, expected;
  std::vector<std::size_t> gotEnds, expectedEnds;
  RunStats gotStats, expectedStats;
  for (int handOver = 0; handOver < 2; ++handOver) {  // appended to, as runBatch's contract says
    recorder.runBatch(spansOf(cells), {}, got, gotEnds, gotStats);
    plain.runBatch(spansOf(cells), {}, expected, expectedEnds, expectedStats);
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(gotEnds, expectedEnds);
  EXPECT_EQ(gotStats.deviceCycles(), expectedStats.deviceCycles());
  ASSERT_EQ(recording.size(), 2u);
  EXPECT_EQ(recording[1].cellEnds.size(), cells.size());
  EXPECT_EQ(recording[1].cellEnds.back(), recording[1].pairs.size());  // its own: counted from 0
  EXPECT_EQ(2 * recording[1].pairs.size(), got.size());
  std::vector<Pair> single;
  RunStats s;
  EXPECT_THROW(recorder.run(cells[0], single, s), std::logic_error);
  EXPECT_THROW(RecordingBackend(nullptr, recording), std::invalid_argument);
}

TEST(PacedBackend, AnswersWithTheRecordingNoSoonerThanItsModelledTime) {
  AnswerRecording recording;
  ModelBackend model(DeviceParams::seed(2, 64, 5));
  RecordingBackend recorder(std::make_unique<ModelBackend>(DeviceParams::seed(2, 64, 5)), recording);
  const auto cells = someCells();
  std::vector<Pair> recorded;
  std::vector<std::size_t> recordedEnds;
  RunStats recordedStats;
  recorder.runBatch(spansOf(cells), {}, recorded, recordedEnds, recordedStats);

  PipelineModel slow;  // a slow clock: the hold is long enough to tell from no hold at all
  slow.clockHz = 1e4;
  slow.link.latencySeconds = 1e-4;
  PacedBackend paced(recording, model, slow);
  EXPECT_EQ(paced.capacity(), model.capacity());
  EXPECT_EQ(paced.bipartite(), model.bipartite());
  const auto t = handOverTimes(recordedStats, slow);
  const double hold = 2 * slow.link.latencySeconds + t.loadSeconds + std::max(t.computeSeconds, t.resultsSeconds);
  ASSERT_GT(hold, 1e-3);
  std::vector<Pair> got;
  std::vector<std::size_t> ends;
  RunStats stats;
  const auto start = PacedBackend::Clock::now();
  paced.rewind(start);
  paced.runBatch(spansOf(cells), {}, got, ends, stats);
  EXPECT_GE(std::chrono::duration<double>(PacedBackend::Clock::now() - start).count(), hold);
  EXPECT_EQ(got, recorded);
  EXPECT_EQ(ends, recordedEnds);
  EXPECT_EQ(stats.deviceCycles(), recordedStats.deviceCycles());
  ASSERT_EQ(paced.spans().size(), 1u);
  ASSERT_EQ(paced.spans()[0].size(), 1u);
  EXPECT_GE(paced.spans()[0][0].second - paced.spans()[0][0].first, hold);
  ASSERT_EQ(paced.lateSeconds().size(), 1u);
  EXPECT_GE(paced.lateSeconds()[0], 0);

  // One hand-over more than recorded, or another cell count, is not the recorded frame.
  EXPECT_THROW(paced.runBatch(spansOf(cells), {}, got, ends, stats), std::logic_error);
  paced.rewind(PacedBackend::Clock::now());
  const auto fewer = std::vector<std::vector<KeyBox>>(cells.begin(), cells.begin() + 2);
  EXPECT_THROW(paced.runBatch(spansOf(fewer), {}, got, ends, stats), std::logic_error);
  slow.clockHz = 0;
  EXPECT_THROW(PacedBackend(recording, model, slow), std::invalid_argument);
}

TEST(PacedBroadPhase, PolledHandOversAgainstThePacedDeviceGiveTheRecordedFramesPairs) {
  for (const auto& [name, boxes] : adversarialScenes(600, 31)) {
    AnswerRecording recording;
    RecordingBackend recorder(std::make_unique<ModelBackend>(DeviceParams::seed(2, 64, 5)), recording);
    BroadPhaseConfig config{
        .cellSize = 16, .partition = PartitionKind::UniformGrid, .cellsPerBatch = 8, .firstBatchCells = 2};
    BroadPhase sync(recorder, config);
    config.handOvers = HandOvers::Polled;
    PacedBroadPhase polled(recording, recorder, PipelineModel{}, config);
    EXPECT_EQ(polled.phase().config().handOvers, HandOvers::Polled);
    for (int frame = 0; frame < 2; ++frame) {
      recording.clear();
      std::vector<Pair> expected, pairs;
      sync.findPairs(boxes, expected);
      polled.awakenDevice();
      polled.findPairs(boxes, pairs);
      EXPECT_EQ(pairs, expected) << name;
      EXPECT_EQ(sorted(pairs), bruteForce(boxes)) << name;
      EXPECT_EQ(polled.phase().stats().deviceCycles(), sync.stats().deviceCycles()) << name;
      EXPECT_EQ(polled.device().spans().size(), static_cast<std::size_t>(frame + 1)) << name;  // rewound each frame
    }
  }
}
