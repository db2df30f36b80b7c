#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <vector>

#include "core/box_file.hpp"
#include "core/broadmark_file.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using bpaccel::testing::sameBits;

namespace {

// Float bit patterns written out, so the hand-built file does not lean on
// the code under test to encode floats.
constexpr std::uint32_t kZero = 0x00000000, kHalf = 0x3f000000, kOne = 0x3f800000, kTwo = 0x40000000,
                        kThree = 0x40400000, kMinusOneAndHalf = 0xbfc00000;

void le32(std::string& s, std::uint32_t v) {
  s.push_back(static_cast<char>(v & 0xff));
  s.push_back(static_cast<char>((v >> 8) & 0xff));
  s.push_back(static_cast<char>((v >> 16) & 0xff));
  s.push_back(static_cast<char>((v >> 24) & 0xff));
}

void name128(std::string& s, const std::string& text) {
  s += text;
  s.append(128 - text.size(), '\0');
}

// min x y z, 0, max x y z, 0: Broadmark's Vec3 is four floats.
void box(std::string& s, std::uint32_t x0, std::uint32_t y0, std::uint32_t z0, std::uint32_t x1, std::uint32_t y1,
         std::uint32_t z1) {
  for (std::uint32_t v : {x0, y0, z0, kZero, x1, y1, z1, kZero}) le32(s, v);
}

// A scene as Broadmark's SimulationGenerator lays it out: "FreeFall", "Cubes",
// 2 objects, 1 frame after the initial one, world box = the boxes' union.
std::string handBuiltScene() {
  std::string s;
  name128(s, "FreeFall");
  name128(s, "Cubes");
  le32(s, 2);  // objects
  le32(s, 1);  // frames after the initial one
  le32(s, 0);  // padding
  le32(s, 0);
  box(s, kMinusOneAndHalf, kZero, kZero, kThree, kOne, kOne);  // world
  box(s, kZero, kZero, kZero, kOne, kOne, kOne);               // frame 0, box 0
  box(s, kTwo, kZero, kZero, kThree, kOne, kOne);              // frame 0, box 1
  box(s, kMinusOneAndHalf, kZero, kZero, kHalf, kOne, kOne);   // frame 1, box 0
  box(s, kTwo, kHalf, kZero, kThree, kOne, kOne);              // frame 1, box 1
  return s;
}

std::string errorOf(const std::string& bytes, std::uint64_t frame = 0) {
  std::istringstream in(bytes);
  try {
    BroadmarkReader reader(in);
    reader.readFrame(frame);
  } catch (const BroadmarkError& e) {
    return e.what();
  }
  return "accepted";
}

std::string withWord(std::string bytes, std::size_t at, std::uint32_t v) {
  std::string word;
  le32(word, v);
  bytes.replace(at, 4, word);
  return bytes;
}

}  // namespace

TEST(Broadmark, AHandBuiltFileInBroadmarksLayoutReadsAsItsBoxes) {
  const std::string bytes = handBuiltScene();
  ASSERT_EQ(bytes.size(), 304u + 32u * 2u * 2u);
  std::istringstream in(bytes);
  BroadmarkReader reader(in);
  const auto& h = reader.header();
  EXPECT_EQ(h.sceneName, "FreeFall");
  EXPECT_EQ(h.objectsType, "Cubes");
  EXPECT_EQ(h.objects, 2u);
  EXPECT_EQ(h.steps, 1u);
  EXPECT_EQ(h.frames(), 2u);
  EXPECT_TRUE(sameBits(h.world, Aabb{{-1.5f, 0, 0}, {3, 1, 1}}));
  const auto frame0 = reader.readFrame(0), frame1 = reader.readFrame(1);
  ASSERT_EQ(frame0.size(), 2u);
  ASSERT_EQ(frame1.size(), 2u);
  EXPECT_TRUE(sameBits(frame0[0], Aabb{{0, 0, 0}, {1, 1, 1}}));
  EXPECT_TRUE(sameBits(frame0[1], Aabb{{2, 0, 0}, {3, 1, 1}}));
  EXPECT_TRUE(sameBits(frame1[0], Aabb{{-1.5f, 0, 0}, {0.5f, 1, 1}}));
  EXPECT_TRUE(sameBits(frame1[1], Aabb{{2, 0.5f, 0}, {3, 1, 1}}));
  // Frames can be read in any order, again.
  EXPECT_TRUE(sameBits(reader.readFrame(0)[1], frame0[1]));
}

TEST(Broadmark, TheWriterWritesBroadmarksLayoutByteForByte) {
  const std::vector<std::vector<Aabb>> frames = {{{{0, 0, 0}, {1, 1, 1}}, {{2, 0, 0}, {3, 1, 1}}},
                                                 {{{-1.5f, 0, 0}, {0.5f, 1, 1}}, {{2, 0.5f, 0}, {3, 1, 1}}}};
  std::ostringstream out;
  writeBroadmark(out, {.sceneName = "FreeFall", .objectsType = "Cubes"}, frames);
  EXPECT_EQ(out.str(), handBuiltScene());
}

TEST(Broadmark, TextToAabbsToTextGivesTheSameBoxesBitForBit) {
  std::mt19937 rng(45);
  std::uniform_real_distribution<float> coord(-1000, 1000), size(0, 50);
  std::vector<Aabb> boxes;
  // More than one read chunk (8192 boxes), and the values text round trips must keep.
  for (int i = 0; i < 10000; ++i) {
    const float x = coord(rng), y = coord(rng), z = coord(rng);
    boxes.push_back({{x, y, z}, {x + size(rng), y + size(rng), z}});
  }
  constexpr float kInf = std::numeric_limits<float>::infinity();
  boxes.push_back({{-0.0f, 0.0f, std::numeric_limits<float>::denorm_min()}, {0.0f, kInf, 1e-40f}});
  boxes.push_back({{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}});
  std::ostringstream text;
  writeBoxes(text, boxes);
  std::istringstream textIn(text.str());
  const std::vector<Aabb> fromText = readBoxes(textIn);

  std::vector<std::vector<Aabb>> frames = {fromText, fromText};
  std::reverse(frames[1].begin(), frames[1].end());
  std::stringstream aabbs;
  writeBroadmark(aabbs, {}, frames);
  BroadmarkReader reader(aabbs);
  EXPECT_EQ(reader.header().sceneName, "bpaccel");
  EXPECT_EQ(reader.header().objectsType, "Assorted");
  EXPECT_TRUE(sameBits(reader.header().world, Aabb{{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}}));
  const auto back = reader.readFrame(0);
  ASSERT_EQ(back.size(), boxes.size());
  for (std::size_t i = 0; i < back.size(); ++i) ASSERT_TRUE(sameBits(back[i], fromText[i])) << i;
  EXPECT_TRUE(sameBits(reader.readFrame(1).front(), fromText.back()));
  std::ostringstream textAgain;
  writeBoxes(textAgain, back);
  EXPECT_EQ(textAgain.str(), text.str());
}

TEST(Broadmark, HeaderFaultsNameTheirFieldAndByte) {
  const std::string good = handBuiltScene();
  EXPECT_EQ(errorOf(""), "byte 0: truncated header: the file has 0 bytes, a header 304");
  EXPECT_EQ(errorOf(good.substr(0, 100)), "byte 100: truncated header: the file has 100 bytes, a header 304");
  std::string name = good;
  name.replace(0, 128, std::string(128, 'A'));
  EXPECT_EQ(errorOf(name), "byte 0: scene name has no terminating zero");
  name = good;
  name[2] = '\a';
  EXPECT_EQ(errorOf(name), "byte 0: scene name character 2 is 0x07, not printable ASCII");
  name = good;
  name[0] = '\0';
  EXPECT_EQ(errorOf(name), "byte 0: scene name is empty");
  name = good;
  name[128 + 100] = 'x';
  EXPECT_EQ(errorOf(name), "byte 128: objects type has nonzero bytes after its terminating zero");
  EXPECT_EQ(errorOf(withWord(good, 256, 0)), "byte 256: number of objects 0 is not positive");
  EXPECT_EQ(errorOf(withWord(good, 256, 0xfffffffb)), "byte 256: number of objects -5 is not positive");
  EXPECT_EQ(errorOf(withWord(good, 260, 0)),
            "byte 260: number of frames 0 is not positive (a scene holds an initial frame and at least one more)");
  EXPECT_EQ(errorOf(withWord(good, 268, 7)), "byte 268: padding is 7, not 0");
  EXPECT_EQ(errorOf(withWord(withWord(good, 272, kThree), 288, kTwo)), "byte 272: world box: minx 3 > maxx 2");
  EXPECT_EQ(errorOf(withWord(good, 272 + 12, kOne)), "byte 272: world box: min's fourth float is 1, not 0");
}

TEST(Broadmark, ALengthOtherThanTheHeadersPromiseIsRefusedNamingTheFrame) {
  const std::string good = handBuiltScene();
  EXPECT_EQ(errorOf(good.substr(0, good.size() - 10)),
            "byte 422: truncated: the header promises frames 0 to 1 of 2 boxes (64 bytes each); the file ends in "
            "frame 1, after 54 of its bytes");
  EXPECT_EQ(errorOf(good.substr(0, 304)),
            "byte 304: truncated: the header promises frames 0 to 1 of 2 boxes (64 bytes each); the file ends in "
            "frame 0, after 0 of its bytes");
  // A header that promises more objects than the file holds: the same check.
  EXPECT_NE(errorOf(withWord(good, 256, 0x7fffffff)).find("byte 432: truncated: the header promises frames 0 to 1 of "
                                                          "2147483647 boxes"),
            std::string::npos);
  EXPECT_EQ(errorOf(good + "abc"), "byte 432: 3 bytes after the last frame (2 frames of 2 boxes)");
}

TEST(Broadmark, BoxFaultsNameTheFrameTheBoxTheFieldAndTheByte) {
  const std::string good = handBuiltScene();
  const std::size_t frame1box1 = 304 + 3 * 32;
  const std::string nan = withWord(good, frame1box1 + 16 + 4, 0x7fc00000);  // maxy
  EXPECT_EQ(errorOf(nan, 1), "byte 400: frame 1, box 1: maxy is NaN");
  EXPECT_EQ(errorOf(nan, 0), "accepted") << "only the frame read is checked";
  EXPECT_EQ(errorOf(withWord(good, 304 + 8, kTwo)), "byte 304: frame 0, box 0: minz 2 > maxz 1");
  EXPECT_EQ(errorOf(withWord(good, 304 + 64 + 28, kOne), 1), "byte 368: frame 1, box 0: max's fourth float is 1, not 0");
  // Infinities are boxes, as in the text format.
  EXPECT_EQ(errorOf(withWord(good, 304, 0xff800000)), "accepted");
}

TEST(Broadmark, AFrameTheFileDoesNotHoldIsOutOfRange) {
  std::istringstream in(handBuiltScene());
  BroadmarkReader reader(in);
  try {
    reader.readFrame(2);
    FAIL() << "frame 2 read";
  } catch (const std::out_of_range& e) {
    EXPECT_STREQ(e.what(), "no frame 2: the scene holds frames 0 to 1");
  }
}

TEST(Broadmark, AStreamThatCannotSeekIsRefused) {
  struct NoSeek : std::streambuf {};  // seekoff fails, as on a pipe
  NoSeek buffer;
  std::istream in(&buffer);
  try {
    BroadmarkReader reader(in);
    FAIL() << "read";
  } catch (const BroadmarkError& e) {
    EXPECT_STREQ(e.what(), "byte 0: cannot find the file's length (a .aabbs file must be seekable)");
  }
}

TEST(Broadmark, TheWriterRefusesWhatBroadmarkWouldRefuseBeforeWriting) {
  const std::vector<Aabb> two = {{{0, 0, 0}, {1, 1, 1}}, {{2, 0, 0}, {3, 1, 1}}};
  auto errorOfWrite = [](const BroadmarkNames& names, const std::vector<std::vector<Aabb>>& frames) {
    std::ostringstream out;
    try {
      writeBroadmark(out, names, frames);
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(out.str(), "");
      return std::string(e.what());
    }
    return std::string("written");
  };
  EXPECT_EQ(errorOfWrite({}, {two}), ".aabbs: 1 frames; a scene holds an initial frame and at least one more");
  EXPECT_EQ(errorOfWrite({}, {two, {two[0]}}), ".aabbs: frame 1 has 1 boxes, frame 0 has 2");
  EXPECT_EQ(errorOfWrite({}, {{}, {}}), ".aabbs: a scene holds at least one box");
  EXPECT_EQ(errorOfWrite({.sceneName = ""}, {two, two}), ".aabbs: scene name is empty");
  EXPECT_EQ(errorOfWrite({.sceneName = std::string(128, 'a')}, {two, two}),
            ".aabbs: scene name has 128 characters, at most 127");
  EXPECT_EQ(errorOfWrite({.objectsType = "caf\xc3\xa9"}, {two, two}),
            ".aabbs: objects type character 3 is 0xc3, not printable ASCII");
  const std::vector<Aabb> nan = {two[0], {{2, 0, 0}, {3, std::nanf(""), 1}}};
  EXPECT_EQ(errorOfWrite({}, {two, nan}), ".aabbs: frame 1, box 1: maxy is NaN");
  EXPECT_EQ(errorOfWrite({.sceneName = std::string(127, 'a')}, {two, two}), "written");
}
