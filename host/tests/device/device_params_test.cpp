#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "bpaccel_params.h"
#include "device/built_device.hpp"
#include "device/device_params.hpp"
#include "device/model_backend.hpp"

using namespace bpaccel;

TEST(DeviceParams, TheBuiltDeviceIsTheGeneratorsHeaderArchitectureIncluded) {
  const DeviceParams p = builtDeviceParams();
  EXPECT_EQ(architectureName(p.architecture), std::string(BPACCEL_ARCH));
  EXPECT_EQ(p.lanes, std::size_t{BPACCEL_M});
  EXPECT_EQ(p.capacity, std::size_t{BPACCEL_CAPACITY});
  EXPECT_EQ(p.keyWidth, unsigned{BPACCEL_KEY_WIDTH});
  EXPECT_EQ(p.bipartiteRuns, BPACCEL_BIPARTITE_RUNS != 0);
  EXPECT_EQ(p.batchOverlapsLoads, BPACCEL_BATCH_OVERLAPS_LOADS != 0);
  EXPECT_NO_THROW(p.check());
  // The model of it runs bipartite exactly where the hardware does: the
  // architecture is named, not inferred from a latency.
  EXPECT_EQ(ModelBackend(p).bipartite(), BPACCEL_BIPARTITE_RUNS != 0);
  EXPECT_EQ(p.resultBeatBytes(), std::size_t{(2 * BPACCEL_INDEX_WIDTH + BPACCEL_M + 7) / 8});
  EXPECT_EQ(p.loadBoxBytes(), std::size_t{(6 * BPACCEL_KEY_WIDTH + 7) / 8});
}

TEST(DeviceParams, ArchitecturesParseFromTheGeneratorsSpellingAndRejectOthers) {
  EXPECT_EQ(parseArchitecture("seed"), Architecture::Seed);
  EXPECT_EQ(parseArchitecture("stream"), Architecture::Stream);
  EXPECT_THROW(parseArchitecture("Stream"), std::invalid_argument);
  EXPECT_THROW(parseArchitecture(""), std::invalid_argument);
}

TEST(DeviceParams, RefusesWhatNoGeneratedDeviceIs) {
  EXPECT_NO_THROW(DeviceParams::seed(4, 64, 5).check());
  EXPECT_NO_THROW(DeviceParams::stream(3, 64, 5, 4).check());
  DeviceParams p = DeviceParams::seed(4, 63, 5);  // the seed stripes objects over its m memories
  EXPECT_THROW(p.check(), std::invalid_argument);
  p = DeviceParams::seed(4, 64, 5);
  p.bipartiteRuns = true;  // the seed's hardware refuses a split
  EXPECT_THROW(p.check(), std::invalid_argument);
  EXPECT_THROW(ModelBackend{p}, std::invalid_argument);
  for (const unsigned width : {0u, 33u}) {
    p = DeviceParams::stream(2, 8, 3, 4);
    p.keyWidth = width;
    EXPECT_THROW(p.check(), std::invalid_argument) << width;
  }
  p = DeviceParams::stream(2, 8, 3, 4);
  p.batchCells = 0;
  EXPECT_THROW(p.check(), std::invalid_argument);
  // A seed device starts its runs at once, whatever read latency it is given.
  p = DeviceParams::seed(2, 8, 3);
  p.readLatency = 9;
  EXPECT_EQ(p.startupCycles(), 0u);
  EXPECT_EQ(DeviceParams::stream(2, 8, 3, 4).startupCycles(), 4u);
}
