// The C++ model of the binning device: its cycles, phases and pairs against
// vectors bpaccel.binning.BinningCycleModel wrote (BinningVectors), the
// exactly-once rule against brute force, the protocol's errors, and a mutant.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <random>

#include <nlohmann/json.hpp>

#include "device/binning/binning_model.hpp"
#include "device/binning/binning_timeline.hpp"
#include "device/binning/key_scenes.hpp"
#include "scenes.hpp"

namespace bpaccel {
namespace {

using testing::below;
using testing::randomKeys;
using testing::sorted;
const auto& bruteForce = testing::bruteForceKeys;

std::uint64_t pairHash(std::uint32_t i, std::uint32_t j) {  // BinningVectors.pairHash
  std::uint64_t z = (std::uint64_t{i} << 32) + j + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

TEST(BinningModel, MatchesTheScalaCycleModelOnEveryVector) {
  std::ifstream in(BPACCEL_BINNING_VECTORS);
  ASSERT_TRUE(in) << BPACCEL_BINNING_VECTORS;
  const auto doc = nlohmann::json::parse(in);
  const BinningParams p = builtBinningParams();
  ASSERT_EQ(doc["fingerprint"].get<std::string>(), p.fingerprint)
      << "the vectors were written for another configuration: run BinningVectors again";
  std::size_t frames = 0, withPairs = 0;
  for (const auto& s : doc["scenes"]) {
    SCOPED_TRACE(s["name"].get<std::string>());
    const auto flat = s["keys"].get<std::vector<std::uint32_t>>();
    std::vector<KeyBox> boxes(flat.size() / 6);
    for (std::size_t b = 0; b < boxes.size(); ++b)
      for (int a = 0; a < 3; ++a) boxes[b].min[a] = flat[6 * b + a], boxes[b].max[a] = flat[6 * b + 3 + a];
    FrameCommand f{boxes, s["shift"].get<unsigned>(), s["dims"].get<std::array<unsigned, 3>>(), s["n"].get<std::size_t>()};
    const binning::Binned binned = binning::bin(p, f);
    std::vector<binning::GroupSchedule> schedules;
    if (binned.ok())
      for (const auto& e : binned.groups) schedules.push_back(binning::scheduleGroup(p, f, e));
    const binning::PlayedFrame played = binning::playFrame(p, f, binned, schedules);
    const FrameReply& r = played.reply;
    EXPECT_EQ(static_cast<int>(r.error), s["error"].get<int>());
    EXPECT_EQ(r.detail, s["detail"].get<std::uint64_t>());
    EXPECT_EQ(r.cycles, s["cycles"].get<std::uint64_t>());
    EXPECT_EQ(r.issueCycles, s["issue_cycles"].get<std::uint64_t>());
    EXPECT_EQ(r.entries, s["entries"].get<std::uint64_t>());
    EXPECT_EQ(r.pairs.size(), s["pairs"].get<std::size_t>());
    std::uint64_t hash = 0;
    for (const auto& [i, j] : r.pairs) hash += pairHash(i, j);
    EXPECT_EQ(std::to_string(hash), s["pair_hash"].get<std::string>());
    if (s.contains("group_done")) {
      EXPECT_EQ(played.intakeDone, s["intake_done"].get<std::uint64_t>());
      EXPECT_EQ(played.sortStart, s["sort_start"].get<std::vector<std::uint64_t>>());
      EXPECT_EQ(played.computeStart, s["compute_start"].get<std::vector<std::uint64_t>>());
      EXPECT_EQ(played.groupDone, s["group_done"].get<std::vector<std::uint64_t>>());
      // The model device's reply is the played one.
      EXPECT_EQ(BinningModel(p).runFrame(f).cycles, r.cycles);
    }
    ++frames;
    withPairs += r.pairs.size() > 10;
  }
  EXPECT_GE(frames, 40u);
  EXPECT_GE(withPairs, 10u);
}

/// Small configurations: several group shapes, lane counts, intake and output widths.
std::vector<BinningParams> smallConfigs() {
  std::vector<BinningParams> out;
  for (auto gb : {std::array<unsigned, 3>{1, 1, 1}, {2, 1, 1}, {1, 2, 2}})
    for (unsigned g : {1u, 2u, 3u}) {
      BinningParams p;
      p.groupBits = gb, p.lanesPerGroup = g, p.keyWidth = 8, p.cellBits = 3;
      p.boxCapacity = 300, p.groupCapacity = 300, p.intakeBoxes = 1 + g % 3, p.pairsPerBeat = 2;
      p.memoryReadLatency = 1 + g % 2, p.itemQueueDepth = 2 * p.memoryReadLatency + 2;
      out.push_back(p);
    }
  return out;
}

TEST(BinningModel, ReportsEveryOverlappingPairExactlyOnceAgainstBruteForce) {
  std::mt19937 rng(41);
  std::size_t frames = 0;
  for (const BinningParams& p : smallConfigs())
    for (std::size_t n : {0, 1, 2, 9, 40, 150})
      for (int kind = 0; kind < 4; ++kind) {
        const unsigned shift = below(rng, p.maxShift() + 1);
        const std::array<unsigned, 3> dims{1 + below(rng, 8), 1 + below(rng, 4), 1 + below(rng, 8)};
        const auto boxes = randomKeys(rng, n, shift, dims, kind);
        const FrameReply r = BinningModel(p).runFrame({boxes, shift, dims, std::nullopt});
        ASSERT_EQ(r.error, FrameError::None) << frameErrorName(r.error) << " box " << r.detail;
        for (const auto& [i, j] : r.pairs) ASSERT_LT(i, j);
        ASSERT_EQ(sorted(r.pairs), bruteForce(boxes)) << "kind " << kind << ", n " << n;  // equal sorted: no duplicate
        ASSERT_GT(r.cycles, 0u);
        ++frames;
      }
  EXPECT_EQ(frames, 9u * 6 * 4);
}

TEST(BinningModel, AMutantWithoutTheExactlyOnceRuleReportsDuplicatesTheCheckCatches) {
  const BinningParams p = smallConfigs()[1];
  std::mt19937 rng(7);
  const auto boxes = randomKeys(rng, 60, 3, {4, 4, 4}, 1);
  const FrameCommand f{boxes, 3, {4, 4, 4}, std::nullopt};
  EXPECT_EQ(sorted(BinningModel(p).runFrame(f).pairs), bruteForce(boxes));
  const auto mutant = sorted(BinningModel(p, {.skipExactlyOnce = true}).runFrame(f).pairs);
  EXPECT_NE(mutant, bruteForce(boxes));
  EXPECT_NE(std::adjacent_find(mutant.begin(), mutant.end()), mutant.end()) << "no pair reported twice";
}

TEST(BinningModel, NamesEachProtocolErrorAndItsFirstOffendingBoxAndSendsNoPair) {
  const BinningParams p = smallConfigs()[0];
  std::mt19937 rng(3);
  std::vector<KeyBox> ok = randomKeys(rng, 30, 4, {4, 4, 4}, 0);
  auto with = [&](std::size_t at, KeyBox b) { auto v = ok; v[at] = b; return v; };
  const KeyBox outside{{0, 0, 0}, {5, 70, 5}}, spans{{0, 0, 0}, {5, 5, 40}}, inverted{{9, 0, 0}, {8, 5, 5}},
      wide{{0, 0, 0}, {300, 5, 5}};
  struct Case { std::vector<KeyBox> boxes; std::optional<std::size_t> n; unsigned shift; FrameError error; std::uint64_t detail; };
  const std::vector<Case> cases = {
      {ok, p.boxCapacity + 1, 4, FrameError::CountOverCapacity, 0},
      {with(17, outside), {}, 4, FrameError::KeyOutOfGrid, 17},
      {with(23, spans), {}, 4, FrameError::BoxSpansCells, 23},
      {with(3, inverted), {}, 4, FrameError::BoxInverted, 3},
      {with(5, wide), {}, 4, FrameError::KeyTooWide, 5},
      {ok, 35, 4, FrameError::LengthMismatch, 30},
      {ok, {}, p.maxShift() + 1, FrameError::BadGrid, 0},
  };
  for (const Case& c : cases) {
    const FrameReply r = BinningModel(p).runFrame({c.boxes, c.shift, {4, 4, 4}, c.n});
    EXPECT_EQ(r.error, c.error) << frameErrorName(c.error) << " expected, got " << frameErrorName(r.error);
    EXPECT_EQ(r.detail, c.detail) << frameErrorName(c.error);
    EXPECT_TRUE(r.pairs.empty());
    EXPECT_GT(r.cycles, p.localCells()) << "an error frame clears the cell tables";
  }
  BinningParams small = p;
  small.groupCapacity = 20;  // 25 boxes in one cell: the 21st finds its group full
  const std::vector<KeyBox> sameCell(25, KeyBox{{1, 1, 1}, {2, 2, 2}});
  const FrameReply r = BinningModel(small).runFrame({sameCell, 4, {4, 4, 4}, std::nullopt});
  EXPECT_EQ(r.error, FrameError::GroupOverflow);
  EXPECT_EQ(r.detail, 20u);
  EXPECT_TRUE(r.pairs.empty());
}

}  // namespace
}  // namespace bpaccel
