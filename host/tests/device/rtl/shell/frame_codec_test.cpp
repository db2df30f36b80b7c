// The FRAME command's encoding and its reply's decoding (docs/protocol.md),
// ready for the binning device.

#include <gtest/gtest.h>

#include "device/rtl/shell/frame_codec.hpp"
#include "reference_shell.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

ShellFormat binning(unsigned boxWords, unsigned indexWidth) {
  return {.wordsPerBeat = 4, .boxWords = boxWords, .indexWords = indexWidth <= 16 ? 1u : 2u, .lanes = 64,
          .indexWidth = indexWidth, .keyWidth = boxWords == 3 ? 16u : 32u, .capacity = 1000, .bipartite = false,
          .cellBits = 4};
}

KeyBox keyBox(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d, std::uint32_t e, std::uint32_t f) {
  return {{a, b, c}, {d, e, f}};
}

}  // namespace

TEST(FrameEncoding, WritesNTheGridAndTheBoxesPaddedToTheBeat) {
  const std::vector<KeyBox> boxes = {keyBox(1, 2, 3, 4, 5, 6), keyBox(0x10, 0x20, 0x30, 0x40, 0x50, 0xFFFF)};
  std::vector<std::uint32_t> packet;
  encodeFrame(binning(3, 10), boxes, {.shift = 5, .cells = {16, 3, 1}}, packet);
  const std::vector<std::uint32_t> expected = {0x0101, 2, 5, 16 | 3 << 8 | 1 << 16,  // FRAME, n, shift, Dx Dy Dz
                                               0x00020001, 0x00040003, 0x00060005,   // box 0, two keys a word
                                               0x00200010, 0x00400030, 0xFFFF0050,   // box 1
                                               0, 0};                                // 12 words: 3 beats
  EXPECT_EQ(packet, expected);
  encodeFrame(binning(6, 20), {}, {.shift = 0, .cells = {1, 1, 1}}, packet);
  EXPECT_EQ(packet, (std::vector<std::uint32_t>{0x0101, 0, 0, 0x010101}));
}

TEST(FrameEncoding, RefusesFramesNoDeviceTakesNamingWhat) {
  const auto message = [](const ShellFormat& f, std::vector<KeyBox> boxes, FrameGrid grid) -> std::string {
    std::vector<std::uint32_t> packet;
    try {
      encodeFrame(f, boxes, grid, packet);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "accepted";
  };
  const KeyBox b = keyBox(1, 1, 1, 2, 2, 2);
  const ShellFormat f = binning(3, 10);
  EXPECT_EQ(message(f, {b}, {.shift = 2, .cells = {16, 16, 16}}), "accepted");
  EXPECT_NE(message(f, {b}, {.shift = 2, .cells = {16, 17, 16}}).find("17 cells on axis 1"), std::string::npos);
  EXPECT_NE(message(f, {b}, {.shift = 2, .cells = {0, 1, 1}}).find("axis 0"), std::string::npos);
  EXPECT_NE(message(f, {b}, {.shift = 32, .cells = {1, 1, 1}}).find("shift"), std::string::npos);
  EXPECT_NE(message(f, std::vector<KeyBox>(1001, b), {}).find("1001 boxes"), std::string::npos);
  EXPECT_NE(message(f, {b, keyBox(1, 1, 0x10000, 2, 2, 2)}, {}).find("box 1"), std::string::npos);
  ShellFormat cellsDevice = f;
  cellsDevice.cellBits = 0;
  EXPECT_NE(message(cellsDevice, {b}, {}).find("bins no frames"), std::string::npos);
}

TEST(FrameReply, DecodesOnePairARecordInBothIndexLayouts) {
  for (const ShellFormat& f : {binning(3, 10), binning(6, 20)}) {
    const std::vector<std::vector<std::uint32_t>> records = {indexWords(f, 3, 7), indexWords(f, 0, 999),
                                                             indexWords(f, 5, 6)};
    const auto reply = packReply(f, records, {.opcode = BPACCEL_SHELL_OP_FRAME, .records = 3, .boxes = 1000,
                                              .pairs = 3});
    EXPECT_EQ(frameReplyWords(f, 3), f.paddedWords(3 * f.indexWords) + 16);
    std::vector<Pair> out = {{1, 2}};
    decodeFrameReply(f, reply, decodeTrailer(f, reply), 1000, out);
    EXPECT_EQ(out, (std::vector<Pair>{{1, 2}, {3, 7}, {0, 999}, {5, 6}})) << f.indexWords;
  }
}

TEST(FrameReply, RefusesPairsOutsideTheFrameAndCountsThatDisagree) {
  const ShellFormat f = binning(6, 20);
  const auto decode = [&](std::vector<std::vector<std::uint32_t>> records, std::uint64_t pairs) -> std::string {
    const auto reply = packReply(f, records, {.opcode = BPACCEL_SHELL_OP_FRAME,
                                              .records = static_cast<std::uint32_t>(records.size()), .pairs = pairs});
    std::vector<Pair> out;
    try {
      decodeFrameReply(f, reply, decodeTrailer(f, reply), 10, out);
    } catch (const ShellProtocolError& e) {
      EXPECT_TRUE(out.empty());
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(decode({indexWords(f, 0, 9)}, 1), "accepted");
  EXPECT_NE(decode({indexWords(f, 0, 9), indexWords(f, 0, 10)}, 2).find("(0, 10)"), std::string::npos);
  EXPECT_NE(decode({indexWords(f, 4, 4)}, 1).find("(4, 4)"), std::string::npos);
  EXPECT_NE(decode({indexWords(f, 0, 9)}, 2).find("counts 2 pairs"), std::string::npos);
}
