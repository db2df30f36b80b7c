// The CELLS command's encoding and its reply's decoding (docs/protocol.md),
// on layouts other than the built one too.

#include <gtest/gtest.h>

#include <random>
#include <set>

#include "device/backend.hpp"
#include "device/rtl/shell/cells_codec.hpp"
#include "reference_shell.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

ShellFormat wideKeys() { return {.wordsPerBeat = 4, .boxWords = 6, .indexWords = 1, .lanes = 8, .indexWidth = 6,
                                  .keyWidth = 32, .capacity = 64, .bipartite = true}; }
ShellFormat narrowKeys() { return {.wordsPerBeat = 2, .boxWords = 3, .indexWords = 2, .lanes = 40, .indexWidth = 17,
                                    .keyWidth = 12, .capacity = 100000, .bipartite = false}; }

KeyBox keyBox(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d, std::uint32_t e, std::uint32_t f) {
  return {{a, b, c}, {d, e, f}};
}

// Cells as the driver takes them.
struct Cells {
  std::vector<std::vector<KeyBox>> boxes;
  std::vector<std::size_t> splits;
  std::vector<std::span<const KeyBox>> spans;
  explicit Cells(std::vector<std::vector<KeyBox>> b, std::vector<std::size_t> s = {})
      : boxes(std::move(b)), splits(std::move(s)) {
    for (const auto& c : boxes) spans.emplace_back(c);
  }
  CellsCommand command() const { return {spans, splits}; }
};

// Random cells of boxes on a small key range (many overlaps), the keys within `keyWidth` bits.
Cells randomCells(std::mt19937& rng, const ShellFormat& f, std::size_t cells, std::size_t most, bool splits) {
  std::vector<std::vector<KeyBox>> boxes(cells);
  std::vector<std::size_t> s;
  const std::uint32_t top = f.keyWidth >= 32 ? 200u : std::min(200u, (1u << f.keyWidth) - 8);
  for (auto& cell : boxes) {
    cell.resize(rng() % (most + 1));
    for (auto& b : cell)
      for (int a = 0; a < 3; ++a) {
        b.min[a] = rng() % top;
        b.max[a] = b.min[a] + rng() % 8;
      }
    s.push_back(splits && cell.size() >= 2 && rng() % 2 ? 1 + rng() % (cell.size() - 1) : 0);
  }
  return Cells(std::move(boxes), splits ? s : std::vector<std::size_t>{});
}

}  // namespace

TEST(CellsEncoding, WritesTheHeaderCellHeadersAndSixKeyWordsPerBoxPaddedToTheBeat) {
  const Cells cells({{keyBox(1, 2, 3, 4, 5, 6), keyBox(7, 8, 9, 10, 11, 12)}, {}}, {1, 0});
  std::vector<std::uint32_t> packet;
  encodeCells(wideKeys(), cells.command(), packet);
  const std::vector<std::uint32_t> expected = {0x0102, 2,                     // CELLS, version 1; two cells
                                               2, 1, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12,  // cell 0, split 1
                                               0, 0,                          // cell 1: empty
                                               0, 0};                         // to 20 words: 5 beats of 4
  EXPECT_EQ(packet, expected);
}

TEST(CellsEncoding, PacksKeysOfSixteenBitsOrFewerTwoAWordLowHalfFirst) {
  const Cells cells({{keyBox(0x001, 0x002, 0x003, 0x004, 0x005, 0xFFF)}});
  std::vector<std::uint32_t> packet;
  encodeCells(narrowKeys(), cells.command(), packet);
  // {min.y, min.x}, {max.x, min.z}, {max.z, max.y}; 7 words padded to 8 (beats of 2).
  const std::vector<std::uint32_t> expected = {0x0102, 1, 1, 0, 0x00020001, 0x00040003, 0x0FFF0005, 0};
  EXPECT_EQ(packet, expected);
}

TEST(CellsEncoding, AnEmptyCommandIsItsHeaderAndACountOfZeroInOneBeat) {
  std::vector<std::uint32_t> packet = {9, 9, 9, 9, 9, 9, 9, 9, 9};  // replaced, not appended to
  encodeCells(wideKeys(), {}, packet);
  EXPECT_EQ(packet, (std::vector<std::uint32_t>{0x0102, 0, 0, 0}));
}

TEST(CellsEncoding, RefusesWhatTheDeviceWouldRefuseNamingTheCellAndBox) {
  const auto message = [](const ShellFormat& f, const Cells& c) -> std::string {
    std::vector<std::uint32_t> packet = {7};
    try {
      encodeCells(f, c.command(), packet);
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(packet, std::vector<std::uint32_t>{7});  // nothing written
      return e.what();
    }
    return "accepted";
  };
  const KeyBox small = keyBox(1, 1, 1, 2, 2, 2);
  ShellFormat f = wideKeys();
  f.capacity = 3;
  EXPECT_EQ(message(f, Cells({{small}, {small, small, small}})), "accepted");
  EXPECT_NE(message(f, Cells({{small}, {small, small, small, small}})).find("cell 1 has 4 boxes"), std::string::npos);
  EXPECT_NE(message(f, Cells({{small, small}, {small, small}}, {0, 2})).find("cell 1 has split 2"), std::string::npos);
  EXPECT_NE(message(f, Cells({{small, small}}, {0, 0})).find("2 splits for 1 cells"), std::string::npos);
  const ShellFormat seedLike = narrowKeys();
  EXPECT_NE(message(seedLike, Cells({{small, small}}, {1})).find("no bipartite runs"), std::string::npos);
  const std::string wide = message(seedLike, Cells({{small}, {small, small, keyBox(1, 1, 1, 2, 0x1000, 2)}}));
  EXPECT_NE(wide.find("cell 1 box 2"), std::string::npos) << wide;
  EXPECT_NE(wide.find("0x1000"), std::string::npos) << wide;
  EXPECT_EQ(message(seedLike, Cells({{keyBox(0xFFF, 0, 0, 0xFFF, 0xFFF, 0xFFF)}})), "accepted");
}

TEST(CellsReply, TheBoundIsARecordPerIssueCycleInWholeBeatsAndTheTrailer) {
  // Ten boxes on 8 lanes issue 9 + 1 cycles (at most a record each); a bipartite run fewer.
  const std::vector<KeyBox> ten(10, keyBox(0, 0, 0, 1, 1, 1));
  const std::vector<std::span<const KeyBox>> cells = {ten, {}, ten};
  EXPECT_EQ(cellsReplyWords(wideKeys(), {cells, {}}), 60u + 16u);  // 20 records of 3 words: 15 beats of 4
  const std::vector<std::size_t> splits = {0, 0, 5};
  const std::uint64_t bipartite = scheduleIssueCycles(10, 8, 5);
  EXPECT_EQ(cellsReplyWords(wideKeys(), {cells, splits}), (10 + bipartite) * 3 / 4 * 4 + ((10 + bipartite) * 3 % 4 ? 4 : 0) + 16);
}

TEST(CellsReply, DecodesEveryPairOfRandomCommandsOnSeveralLayouts) {
  std::mt19937 rng(11);
  for (const ShellFormat& f : {wideKeys(), narrowKeys()})
    for (int round = 0; round < 20; ++round) {
      const Cells cells = randomCells(rng, f, rng() % 6, round < 10 ? 12 : 60, f.bipartite);
      std::vector<std::uint32_t> packet;
      encodeCells(f, cells.command(), packet);
      const auto reply = referenceCellsReply(f, packet);
      ASSERT_LE(reply.size(), cellsReplyWords(f, cells.command()));
      const Trailer trailer = decodeTrailer(f, reply);
      std::vector<Pair> out = {{0, 1}};  // appended to
      std::vector<std::size_t> ends = {1};
      decodeCellsReply(f, reply, trailer, cells.command(), out, ends);
      ASSERT_EQ(ends.size(), 1 + cells.spans.size());
      for (std::size_t k = 0; k < cells.spans.size(); ++k) {
        std::set<Pair> expected;
        const std::size_t split = cells.command().split(k);
        for (std::uint32_t i = 0; i < cells.spans[k].size(); ++i)
          for (std::uint32_t j = i + 1; j < cells.spans[k].size(); ++j)
            if (overlaps(cells.spans[k][i], cells.spans[k][j]) && (split == 0 || (i < split && j >= split)))
              expected.insert({i, j});
        const std::set<Pair> got(out.begin() + static_cast<std::ptrdiff_t>(ends[k]),
                                 out.begin() + static_cast<std::ptrdiff_t>(ends[k + 1]));
        EXPECT_EQ(got, expected) << "cell " << k << " round " << round;
        EXPECT_EQ(ends[k + 1] - ends[k], expected.size()) << "each pair once";
      }
    }
}

TEST(CellsReply, RecordIndicesWrapModuloTheIndexWidthAndMasksSpanSeveralWords) {
  // Lane k of a record is (iBase + k, jBase + k) modulo 2^indexWidth: a short
  // stream run's bases come moved down by its head pad and may wrap.
  ShellFormat f = wideKeys();  // 6-bit indices, 8 lanes
  const std::vector<KeyBox> cell(10, keyBox(0, 0, 0, 1, 1, 1));
  const std::vector<std::span<const KeyBox>> spans = {cell};
  ReferenceTrailer t{.records = 1, .boxes = 10, .cells = 1, .pairs = 2};
  const auto reply = packReply(f, {cellsRecordWords(f, {0, 62, 1, {0b1100}})}, t);  // lanes 2, 3: (0, 3), (1, 4)
  std::vector<Pair> out;
  std::vector<std::size_t> ends;
  decodeCellsReply(f, reply, decodeTrailer(f, reply), {spans, {}}, out, ends);
  EXPECT_EQ(out, (std::vector<Pair>{{0, 3}, {1, 4}}));
  // 40 lanes: two mask words, bit k of word w is lane 32 w + k; two index words.
  f = narrowKeys();
  const std::vector<KeyBox> big(80, keyBox(0, 0, 0, 1, 1, 1));
  const std::vector<std::span<const KeyBox>> bigSpans = {{}, big};
  t = {.records = 1, .boxes = 80, .cells = 2, .pairs = 3};
  const auto wide = packReply(f, {cellsRecordWords(f, {1, 5, 40, {0x1u, 0x81u}})}, t);  // lanes 0, 32, 39
  out.clear();
  ends.clear();
  decodeCellsReply(f, wide, decodeTrailer(f, wide), {bigSpans, {}}, out, ends);
  EXPECT_EQ(out, (std::vector<Pair>{{5, 40}, {37, 72}, {44, 79}}));
  EXPECT_EQ(ends, (std::vector<std::size_t>{0, 3}));
}

TEST(CellsReply, RefusesRepliesThatCannotAnswerTheCommandLeavingTheOutputAsItWas) {
  const ShellFormat f = wideKeys();
  const std::vector<KeyBox> four(4, keyBox(0, 0, 0, 1, 1, 1));
  const std::vector<std::span<const KeyBox>> two = {four, four};
  const std::vector<std::size_t> splits = {0, 2};
  const CellsCommand command{two, splits};
  const auto decode = [&](const std::vector<std::uint32_t>& reply) -> std::string {
    std::vector<Pair> out = {{0, 1}};
    std::vector<std::size_t> ends = {1};
    try {
      decodeCellsReply(f, reply, decodeTrailer(f, reply), command, out, ends);
    } catch (const ShellProtocolError& e) {
      EXPECT_EQ(out.size(), 1u);
      EXPECT_EQ(ends.size(), 1u);
      return e.what();
    }
    return "accepted";
  };
  const auto record = [&](std::uint32_t cell, std::uint32_t i, std::uint32_t j, std::uint32_t mask) {
    return cellsRecordWords(f, {cell, i, j, {mask}});
  };
  ReferenceTrailer ok{.records = 2, .boxes = 8, .cells = 2, .pairs = 2};
  EXPECT_EQ(decode(packReply(f, {record(0, 0, 1, 1), record(1, 1, 2, 1)}, ok)), "accepted");
  EXPECT_NE(decode(packReply(f, {record(1, 1, 2, 1), record(0, 0, 1, 1)}, ok)).find("names cell 0 after cell 1"),
            std::string::npos);
  EXPECT_NE(decode(packReply(f, {record(0, 0, 1, 1), record(2, 0, 1, 1)}, ok)).find("cell 2"), std::string::npos);
  EXPECT_NE(decode(packReply(f, {record(0, 0, 1, 1), record(1, 0, 1, 1)}, ok)).find("split 2"), std::string::npos);
  EXPECT_NE(decode(packReply(f, {record(0, 0, 1, 1), record(1, 1, 4, 1)}, ok)).find("(1, 4)"), std::string::npos);
  EXPECT_NE(decode(packReply(f, {record(0, 0, 1, 1), record(1, 1, 2, 0x100)}, ok)).find("above lane 7"),
            std::string::npos);
  ReferenceTrailer morePairs = ok;
  morePairs.pairs = 3;
  EXPECT_NE(decode(packReply(f, {record(0, 0, 1, 1), record(1, 1, 2, 1)}, morePairs)).find("counts 3 pairs"),
            std::string::npos);
  ReferenceTrailer moreRecords = ok;
  moreRecords.records = 3;  // the words before the trailer hold two
  EXPECT_NE(decode(packReply(f, {record(0, 0, 1, 1), record(1, 1, 2, 1)}, moreRecords)).find("before the trailer"),
            std::string::npos);
}

TEST(CellsReply, TheTrailerNeedsWholeBeatsItsMagicAndSaneCounters) {
  const ShellFormat f = wideKeys();
  const auto words = packReply(f, {}, {.records = 0, .deviceCycles = 9, .intakeCycles = 4});
  const Trailer t = decodeTrailer(f, words);
  EXPECT_EQ(t.deviceCycles, 9u);
  EXPECT_EQ(t.runCycles(), 5u);
  EXPECT_EQ(t.opcode, static_cast<std::uint32_t>(BPACCEL_SHELL_OP_CELLS));
  auto cut = words;
  cut.pop_back();
  EXPECT_THROW(decodeTrailer(f, cut), ShellProtocolError);  // not whole beats
  EXPECT_THROW(decodeTrailer(f, std::vector<std::uint32_t>(12, 0)), ShellProtocolError);  // shorter than a trailer
  auto noMagic = words;
  noMagic[noMagic.size() - 16] &= 0x00FFFFFFu;
  EXPECT_THROW(decodeTrailer(f, noMagic), ShellProtocolError);
  const auto backwards = packReply(f, {}, {.deviceCycles = 3, .intakeCycles = 4});
  EXPECT_THROW(decodeTrailer(f, backwards), ShellProtocolError);
}
