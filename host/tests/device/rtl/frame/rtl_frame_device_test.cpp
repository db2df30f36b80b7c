// The shell driver's FRAME path on the binning device's RTL (the Verilated
// binning shell): pairs, errors with their box and the trailer's counters
// against the C++ model, under stalls on both streams; the probe that
// refuses a driver built for another shell; the host's float frame path,
// regions included, on the RTL against brute force.

#include <gtest/gtest.h>

#include <random>

#include "broad_phase/binning_frame.hpp"
#include "device/binning/binning_model.hpp"
#include "device/binning/key_scenes.hpp"
#include "device/rtl/frame/rtl_frame_device.hpp"
#include "device/rtl/shell/shell_reply.hpp"
#include "scenes.hpp"

namespace bpaccel {
namespace {

using testing::below;
using testing::randomKeys;
using testing::sorted;

/// The RTL's reply against the model's: the same error and box, the same pairs, the counters the trailer carries.
void expectSameAnswer(const FrameReply& rtl, const FrameReply& model, std::size_t n) {
  ASSERT_EQ(rtl.error, model.error) << frameErrorName(rtl.error) << " against the model's " << frameErrorName(model.error);
  EXPECT_EQ(rtl.detail, model.detail);
  EXPECT_EQ(sorted(rtl.pairs), sorted(model.pairs));
  EXPECT_EQ(rtl.pairs.size(), sorted(rtl.pairs).size());
  if (model.error != FrameError::None) return;
  EXPECT_EQ(rtl.issueCycles, model.issueCycles);
  EXPECT_EQ(rtl.boxesReceived, n);
  // The shell's 128-bit stream brings 4/3 boxes a bus cycle; the model's host offers a beat of boxes every cycle.
  EXPECT_GE(rtl.cycles, model.cycles);
}

TEST(RtlFrameDevice, ProbesTheBinningShellAndADriverForTheCellsShellRefusesIt) {
  RtlFrameDevice rtl;
  const BinningParams& p = rtl.params();
  EXPECT_EQ(rtl.driver().format().capacity, p.boxCapacity);
  EXPECT_EQ(rtl.driver().format().keyWidth, p.keyWidth);
  EXPECT_EQ(rtl.driver().format().cellBits, p.cellBits);
  EXPECT_EQ(rtl.driver().format().lanes, p.lanes());
  try {
    ShellDriver cells(rtl.transport(), builtShellIdentity());
    FAIL() << "a driver for the CELLS shell took the binning shell";
  } catch (const ShellProbeError& e) {
    EXPECT_NE(std::string(e.what()).find("ARCH"), std::string::npos) << e.what();
  }
}

TEST(RtlFrameDevice, AgreesWithTheModelOnEverySceneKindUpToTheCapacity) {
  RtlFrameDevice rtl;
  BinningModel model(rtl.params());
  const BinningParams& p = rtl.params();
  std::mt19937 rng(43);
  std::size_t frames = 0, withPairs = 0;
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{37}, std::size_t{150}, p.boxCapacity})
    for (int kind = 0; kind < 4; ++kind) {
      const unsigned shift = below(rng, p.maxShift() + 1);
      const std::array<unsigned, 3> dims{1 + below(rng, p.maxDim()), 1 + below(rng, 4), 1 + below(rng, p.maxDim())};
      const auto boxes = randomKeys(rng, n, shift, dims, kind);
      const FrameCommand f{boxes, shift, dims, std::nullopt};
      SCOPED_TRACE("n " + std::to_string(n) + ", kind " + std::to_string(kind));
      const FrameReply r = rtl.runFrame(f);
      expectSameAnswer(r, model.runFrame(f), n);
      if (r.error == FrameError::None) EXPECT_EQ(sorted(r.pairs), testing::bruteForceKeys(boxes));
      ++frames, withPairs += !r.pairs.empty();
    }
  EXPECT_EQ(frames, 24u);
  EXPECT_GE(withPairs, 8u);
}

TEST(RtlFrameDevice, NamesEachErrorWithItsBoxAsTheModelDoesAndAnswersTheNextFrame) {
  RtlFrameDevice rtl;
  const BinningParams& p = rtl.params();
  BinningModel model(p);
  std::mt19937 rng(3);
  const std::array<unsigned, 3> dims{4, 4, 4};
  const std::vector<KeyBox> ok = randomKeys(rng, 60, 4, dims, 0);
  const auto with = [&](std::size_t at, KeyBox b) { auto v = ok; v[at] = b; return v; };
  const KeyBox outside{{0, 0, 0}, {5, 70, 5}}, spans{{0, 0, 0}, {5, 5, 40}}, inverted{{9, 0, 0}, {8, 5, 5}};
  const std::vector<KeyBox> sameCell(p.groupCapacity + 5, KeyBox{{1, 1, 1}, {2, 2, 2}});
  const std::vector<std::pair<std::vector<KeyBox>, FrameError>> cases = {
      {with(17, outside), FrameError::KeyOutOfGrid},
      {with(23, spans), FrameError::BoxSpansCells},
      {with(3, inverted), FrameError::BoxInverted},
      {sameCell, FrameError::GroupOverflow},
      {ok, FrameError::BadGrid},  // with a shift above the largest
  };
  for (const auto& [boxes, error] : cases) {
    SCOPED_TRACE(std::string(frameErrorName(error)));
    const FrameCommand f{boxes, error == FrameError::BadGrid ? p.maxShift() + 1 : 4, dims, std::nullopt};
    const FrameReply r = rtl.runFrame(f);
    EXPECT_EQ(r.error, error);
    expectSameAnswer(r, model.runFrame(f), boxes.size());
    const FrameCommand next{ok, 4, dims, std::nullopt};
    expectSameAnswer(rtl.runFrame(next), model.runFrame(next), ok.size());
  }
  // Header errors the driver does not send: answered as the device answers them, without a command.
  const std::vector<KeyBox> tooMany(p.boxCapacity + 1, KeyBox{{1, 1, 1}, {2, 2, 2}});
  for (const FrameCommand& f : {FrameCommand{tooMany, 4, dims, std::nullopt},
                                FrameCommand{ok, 4, {4, p.maxDim() + 1, 4}, std::nullopt},
                                FrameCommand{ok, 4, {4, 0, 4}, std::nullopt}})
    expectSameAnswer(rtl.runFrame(f), model.runFrame(f), f.boxes.size());
  // A key wider than the device's: the driver refuses it, naming the box.
  const std::vector<KeyBox> wide = with(5, KeyBox{{0, 0, 0}, {1u << p.keyWidth, 5, 5}});
  EXPECT_THROW(rtl.runFrame({wide, 4, dims, std::nullopt}), std::invalid_argument);
  EXPECT_EQ(rtl.driver().events().commands, 2 * cases.size());
}

TEST(RtlFrameDevice, IsExactWhenBothStreamsStall) {
  std::mt19937 pattern(11);
  RtlFrameDeviceConfig config;
  config.shell.sendReady = [&](std::uint64_t) { return pattern() % 3 != 0; };
  config.shell.replyReady = [&](std::uint64_t) { return pattern() % 4 == 0; };
  RtlFrameDevice rtl(config);
  BinningModel model(rtl.params());
  std::mt19937 rng(12);
  for (int kind = 0; kind < 3; ++kind) {
    const auto boxes = randomKeys(rng, 300, 5, {8, 8, 8}, kind);
    const FrameCommand f{boxes, 5, {8, 8, 8}, std::nullopt};
    expectSameAnswer(rtl.runFrame(f), model.runFrame(f), boxes.size());
  }
  EXPECT_GT(rtl.transport().counters().replyStallCycles, 0u);
}

TEST(RtlFrameDevice, CarriesTheFloatFramePathExactlyWithRegionsAboveItsCapacity) {
  RtlFrameDevice rtl;
  for (std::size_t n : {150, 700})
    for (const auto& [name, boxes] : testing::adversarialScenes(n, 29 + static_cast<unsigned>(n))) {
      SCOPED_TRACE(name + ", n = " + std::to_string(n));
      BinningFrame frame(rtl);
      std::vector<Pair> out;
      frame.findPairs(boxes, out);
      EXPECT_EQ(sorted(out), testing::bruteForce(boxes));
    }
  const auto scattered = testing::scatteredBoxes(1500, 3, 0, 40, 0.1f, 3.0f);
  BinningFrame frame(rtl);
  std::vector<Pair> out;
  frame.findPairs(scattered, out);
  EXPECT_EQ(sorted(out), testing::bruteForce(scattered));
  EXPECT_GE(frame.stats().frames, 3u) << "1500 boxes on a device of 512 took no regions";
  EXPECT_GT(frame.stats().boundaryDrops, 0u);
}

}  // namespace
}  // namespace bpaccel
