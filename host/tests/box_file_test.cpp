#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "box_file.hpp"

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
  EXPECT_EQ(errorOf("0 0 0 1 1 1e99\n"), "line 1: maxz '1e99' is out of float range");
}

TEST(ReadBoxes, RejectsNaN) { EXPECT_EQ(errorOf("\n\nnan 0 0 1 1 1\n"), "line 3: minx is NaN"); }

TEST(ReadBoxes, RejectsMinAboveMax) { EXPECT_EQ(errorOf("0 2 0 1 1 1\n"), "line 1: miny 2 > maxy 1"); }
