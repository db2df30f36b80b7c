#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <vector>

#include "core/box_file.hpp"

using namespace bpaccel;

namespace {

std::string errorOf(const std::string& text) {
  std::istringstream in(text);
  try {
    readBoxes(in);
  } catch (const ParseError& e) {
    return e.what();
  }
  return "accepted";
}

std::vector<Aabb> boxesOf(const std::string& text) {
  std::istringstream in(text);
  return readBoxes(in);
}

}  // namespace

TEST(ReadBoxes, SkipsBlankLinesAndComments) {
  std::istringstream in("# header\n\n0 0 0 1 1 1\n  \t\n2 2 2 3 3 3 # trailing comment\n+1 -1 1e3 2 0 inf\n");
  const auto boxes = readBoxes(in);
  ASSERT_EQ(boxes.size(), 3u);
  EXPECT_EQ(boxes[1].min[0], 2.0f);
  EXPECT_EQ(boxes[2].min[0], 1.0f);
  EXPECT_EQ(boxes[2].min[2], 1000.0f);
  EXPECT_TRUE(std::isinf(boxes[2].max[2]));
}

TEST(ReadBoxes, AcceptsCrLfLineEnds) {
  std::istringstream in("0 0 0 1 1 1\r\n1 1 1 2 2 2\r\n");
  EXPECT_EQ(readBoxes(in).size(), 2u);
}

TEST(ReadBoxes, RejectsWrongFieldCountsWithTheLineNumber) {
  EXPECT_EQ(errorOf("0 0 0 1 1 1\n0 0 0 1 1\n"), "line 2: 5 fields, expected 6 (minx miny minz maxx maxy maxz)");
  EXPECT_EQ(errorOf("# c\n0 0 0 1 1 1 1\n"), "line 2: more than 6 fields (expected minx miny minz maxx maxy maxz)");
}

TEST(ReadBoxes, RejectsTextThatIsNotANumber) {
  EXPECT_EQ(errorOf("0 0 0 1 x 1\n"), "line 1: maxy 'x' is not a number");
  EXPECT_EQ(errorOf("0 0 0 1 1.5.2 1\n"), "line 1: maxy '1.5.2' is not a number");
  EXPECT_EQ(errorOf("0 0 0 1 1 1,\n"), "line 1: maxz '1,' is not a number");
}

TEST(ReadBoxes, RoundsUnderflowsAsStrtofDoes) {
  const float denormMin = std::numeric_limits<float>::denorm_min();
  // 1e-46 is below half the smallest denormal: zero, with its sign.
  const auto b = boxesOf("1e-46 -1e-46 6e-46 1 1 8e-46\n-1e-40 1e-40 1e-45 1e-40 1e-40 1e-38\n");
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(b[0].min[0]), 0x00000000u);
  EXPECT_EQ(std::bit_cast<std::uint32_t>(b[0].min[1]), 0x80000000u);  // -0.0
  EXPECT_EQ(b[0].min[2], 0.0f);                                       // 6e-46 < denormMin / 2
  EXPECT_EQ(b[0].max[2], denormMin);                                  // 8e-46 > denormMin / 2
  // 1e-40 is 71362.38... smallest denormals: the nearest one is 71362 of them.
  EXPECT_EQ(b[1].min[1], 71362 * denormMin);
  EXPECT_EQ(b[1].min[0], -71362 * denormMin);
  EXPECT_EQ(b[1].min[2], denormMin);  // 1e-45 rounds to the smallest denormal
  EXPECT_EQ(b[1].max[2], 1e-38f);     // a normal float, for comparison
}

TEST(ReadBoxes, AcceptsTheLargestFloatAndRejectsBeyondItNamingTheField) {
  const float largest = std::numeric_limits<float>::max();
  // 3.40282356e38 still rounds to the largest float; 3.4028236e38 rounds past it.
  const auto b = boxesOf("-3.40282356e38 0 0 3.4028235e38 1 1\n");
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].min[0], -largest);
  EXPECT_EQ(b[0].max[0], largest);
  EXPECT_EQ(errorOf("0 0 0 1 1 3.4028236e38\n"),
            "line 1: maxz '3.4028236e38' is beyond the float range (largest magnitude 3.4028235e+38); write inf for "
            "an infinite coordinate");
  EXPECT_EQ(errorOf("# x\n-1e99 0 0 1 1 1\n"),
            "line 2: minx '-1e99' is beyond the float range (largest magnitude 3.4028235e+38); write inf for an "
            "infinite coordinate");
  EXPECT_TRUE(std::isinf(boxesOf("-inf 0 0 inf 1 1\n")[0].min[0]));
}

TEST(ReadBoxes, RejectsNaN) { EXPECT_EQ(errorOf("\n\nnan 0 0 1 1 1\n"), "line 3: minx is NaN"); }

TEST(ReadBoxes, RejectsMinAboveMax) { EXPECT_EQ(errorOf("0 2 0 1 1 1\n"), "line 1: miny 2 > maxy 1"); }

TEST(WriteBoxes, WritesBoxesThatReadBackBitForBit) {
  const float tiny = std::numeric_limits<float>::denorm_min(), big = std::numeric_limits<float>::max();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<Aabb> boxes = {{{-0.0f, 1e-30f, -inf}, {0.0f, 0.1f, inf}},
                             {{tiny, -big, 1.0f / 3}, {2 * tiny, big, 3.4e37f}}};
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> any(-1e6f, 1e6f);
  for (int k = 0; k < 3000; ++k) {  // more than one write of the buffer
    Aabb b;
    for (int a = 0; a < 3; ++a) {
      b.min[a] = any(rng);
      b.max[a] = b.min[a] + std::abs(any(rng));
    }
    boxes.push_back(b);
  }
  std::stringstream text;
  writeBoxes(text, boxes);
  const std::vector<Aabb> back = readBoxes(text);
  ASSERT_EQ(back.size(), boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(std::bit_cast<std::uint32_t>(back[i].min[a]), std::bit_cast<std::uint32_t>(boxes[i].min[a])) << i;
      EXPECT_EQ(std::bit_cast<std::uint32_t>(back[i].max[a]), std::bit_cast<std::uint32_t>(boxes[i].max[a])) << i;
    }
}
