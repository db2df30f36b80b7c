#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "model/timeline.hpp"

using namespace bpaccel;

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
