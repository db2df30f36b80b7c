// The binning rows' frame model: what the link and the device are charged.

#include <gtest/gtest.h>

#include "methods/binning_method.hpp"
#include "scenes.hpp"

namespace bpaccel {
namespace {

DeviceProfile testProfile() {
  DeviceProfile p;
  p.name = "test";
  p.part.clockHz = {100e6, Provenance::Assumed, "test"};
  p.link.effectiveBytesPerSecond = {1e9, Provenance::Assumed, "test"};
  p.link.latencySeconds = {1e-6, Provenance::Assumed, "test"};
  return p;
}

TEST(BinningMethod, ChargesTheDeviceItsCyclesAndTheLinkEachBoxOnceBeyondTheIntake) {
  BinningParams params;  // kw = 12: a box is 3 words; 13-bit indices: a pair is a word
  BinningFrameStats s;
  s.slabs = 2;
  s.boxesSent = 10000;
  s.devicePairs = 5000;
  s.deviceCycles = 9000;
  s.phases.intake = 5000;  // 50 us at 100 MHz
  const BinningFrameModel m = modelBinningFrame(s, params, testProfile());
  EXPECT_DOUBLE_EQ(m.deviceSeconds, 9000 / 100e6);
  const double boxes = (10000 * 12 + 2 * 16) / 1e9, back = (5000 * 4 + 2 * 32) / 1e9;
  EXPECT_DOUBLE_EQ(m.transferSeconds, 2 * 2 * 1e-6 + (boxes - 50e-6) + back);
  s.phases.intake = 50000;  // an intake slower than the link hides the boxes' bytes
  EXPECT_DOUBLE_EQ(modelBinningFrame(s, params, testProfile()).transferSeconds, 2 * 2 * 1e-6 + back);
  EXPECT_EQ(frameBoxBytes(16), 12u);
  EXPECT_EQ(frameBoxBytes(17), 24u);
}

TEST(BinningMethod, FindsTheExactPairsAndCountsOnlyHostWorkAsHost) {
  BinningParams params;
  params.fingerprint = "test";
  BinningMethod method(params, testProfile());
  const auto boxes = testing::scatteredBoxes(500, 2, 0, 20, 0.5f, 2.0f);
  method.update(boxes);
  std::vector<Pair> got;
  method.pairs(got);
  EXPECT_EQ(testing::sorted(got), testing::bruteForce(boxes));
  const FrameTime t = method.frameTime(1.0);
  ASSERT_TRUE(t.parts);
  EXPECT_LT(t.parts->hostSeconds, 1.0);  // the model's own run is not host work
  EXPECT_GT(t.parts->deviceSeconds, 0);
  EXPECT_EQ(t.parts->stats.boxesSent, 500u);
  EXPECT_DOUBLE_EQ(t.seconds, t.parts->hostSeconds + t.parts->deviceSeconds + t.parts->transferSeconds);
}

}  // namespace
}  // namespace bpaccel
