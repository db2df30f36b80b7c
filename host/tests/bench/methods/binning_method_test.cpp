// The binning rows' frame model: what the link and the device are charged.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include <nlohmann/json.hpp>

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
  s.frames = 2;
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
  EXPECT_GE(method.planSeconds(), 0.0);
  EXPECT_GE(method.driverSeconds(), 0.0);
  EXPECT_GE(method.collectSeconds(), 0.0);
}

TEST(BinningMethod, RunsAtTheBinningDesignsOwnClockWhereItsReportOnThePartIsValidElseTheStreamsStandsIn) {
  const auto dir = std::filesystem::temp_directory_path() / ("binning-reports-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& status, double mhz) {
    std::ofstream(dir / name) << nlohmann::json{{"status", status}, {"result_valid", status == "ok"}, {"m", 64},
                                                {"arch", "binning"}, {"key_width", 12}, {"ecp5", {{"fmax_mhz", mhz}}}}
                                     .dump();
  };
  BinningParams params;  // 64 lanes, 12-bit keys: reports binning-m64[-lfe5um5g-85f].json
  DeviceProfile fiveG = testProfile(), gen3 = testProfile();
  fiveG.name = "ecp5-5g", fiveG.part.name = "LFE5UM5G-85F", fiveG.part.speedGrade = 8;
  gen3.name = "gen3x8";
  for (DeviceProfile* p : {&fiveG, &gen3}) p->part.clockHz = {83.8e6, Provenance::Measured, "the stream device's"};

  // No reports: the stream device's clock stands in, and says which report is missing.
  DeviceProfile b = binningProfile(fiveG, params, dir.string());
  EXPECT_EQ(b.part.clockHz.value, 83.8e6);
  EXPECT_EQ(b.part.clockHz.provenance, Provenance::StandIn);
  EXPECT_NE(b.part.clockHz.source.find("binning-m64"), std::string::npos) << b.part.clockHz.source;
  // A report of a design that does not fit: still the stand-in, naming the report.
  write("binning-m64-lfe5um5g-85f.json", "does_not_fit", 0);
  b = binningProfile(fiveG, params, dir.string());
  EXPECT_EQ(b.part.clockHz.value, 83.8e6);
  EXPECT_NE(b.part.clockHz.source.find("binning-m64-lfe5um5g-85f.json"), std::string::npos) << b.part.clockHz.source;
  // A routed design on the 5G part: its own Fmax, measured; the gen3x8 card takes the LFE5U-85F's as a stand-in.
  write("binning-m64-lfe5um5g-85f.json", "ok", 131.5);
  write("binning-m64.json", "ok", 101.25);
  b = binningProfile(fiveG, params, dir.string());
  EXPECT_EQ(b.part.clockHz.value, 131.5e6);
  EXPECT_EQ(b.part.clockHz.provenance, Provenance::Measured);
  const DeviceProfile g = binningProfile(gen3, params, dir.string());
  EXPECT_EQ(g.part.clockHz.value, 101.25e6);
  EXPECT_EQ(g.part.clockHz.provenance, Provenance::StandIn);
  EXPECT_EQ(g.link.effectiveBytesPerSecond.value, gen3.link.effectiveBytesPerSecond.value);
  std::filesystem::remove_all(dir);
}

TEST(BinningMethod, TheModelledCardRunsTheDriversEncodingAndDecodingAndReturnsTheModelsPairs) {
  BinningModel model(builtBinningParams()), inner(builtBinningParams());
  ModelledFrameCard card(inner);
  BinningFrame direct(model), driven(card);
  const auto boxes = testing::scatteredBoxes(3000, 4, 0, 40, 0.3f, 2.5f);
  std::vector<Pair> a, b;
  direct.findPairs(boxes, a);
  driven.findPairs(boxes, b);
  std::sort(a.begin(), a.end()), std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
  EXPECT_GT(b.size(), 0u);
  EXPECT_EQ(driven.stats().deviceCycles, direct.stats().deviceCycles);
  EXPECT_GT(card.seconds, 0.0);
  // A key wider than the device's is the driver's to refuse, before the card sees it.
  std::vector<KeyBox> wide(1, KeyBox{{0, 0, 0}, {1u << 20, 1, 1}});
  EXPECT_THROW(card.runFrame(FrameCommand{wide, 0, {1, 1, 1}, std::nullopt}), std::invalid_argument);
}

/// A FrameDevice that counts the frames it runs, in front of a model.
class CountingDevice final : public FrameDevice {
 public:
  explicit CountingDevice(FrameDevice& inner) : inner_(inner) {}
  std::string name() const override { return inner_.name(); }
  const BinningParams& params() const override { return inner_.params(); }
  FrameReply runFrame(const FrameCommand& command) override { return ++runs, inner_.runFrame(command); }
  std::size_t runs = 0;

 private:
  FrameDevice& inner_;
};

TEST(BinningMethod, TheReplayGivesTheRecordedRepliesWithoutRunningTheModelAndRefusesAnotherCommand) {
  BinningParams small = builtBinningParams();
  small.boxCapacity = 1000;  // 3000 boxes: several frames
  BinningModel model(small);
  CountingDevice counted(model);
  ModelledFrameCard card(counted);
  BinningFrame frame(card);
  const auto boxes = testing::scatteredBoxes(3000, 5, 0, 40, 0.3f, 2.5f);
  std::vector<Pair> recorded, replayed;
  card.record();
  frame.findPairs(boxes, recorded);
  const std::size_t runs = counted.runs;
  const BinningFrameStats first = frame.stats();
  EXPECT_GE(runs, 3u);
  card.replay();
  frame.findPairs(boxes, replayed);
  EXPECT_EQ(counted.runs, runs) << "the replay ran the model";
  EXPECT_EQ(testing::sorted(replayed), testing::sorted(recorded));
  EXPECT_EQ(testing::sorted(replayed), testing::bruteForce(boxes));
  EXPECT_EQ(frame.stats().deviceCycles, first.deviceCycles);
  EXPECT_EQ(frame.stats().frames, first.frames);
  // Another scene's commands are not the recorded ones.
  card.replay();
  const auto moved = testing::scatteredBoxes(3000, 6, 0, 40, 0.3f, 2.5f);
  EXPECT_THROW(frame.findPairs(moved, replayed), std::logic_error);
}

}  // namespace
}  // namespace bpaccel
