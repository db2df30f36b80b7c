#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "keys.hpp"

using namespace bpaccel;

TEST(FloatToKey, PreservesTheOrderOfFloats) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> ascending = {-inf, -3.4e38f, -1e10f, -2.5f, -1.0f, -1e-30f, -1e-45f, 0.0f,
                                        1e-45f, 1e-38f, 1e-30f, 0.5f, 1.0f, 2.0f, 1e10f, 3.4e38f, inf};
  for (std::size_t i = 0; i + 1 < ascending.size(); ++i)
    EXPECT_LT(floatToKey(ascending[i]), floatToKey(ascending[i + 1])) << ascending[i] << " vs " << ascending[i + 1];
}

TEST(FloatToKey, MapsBothZerosToOneKey) { EXPECT_EQ(floatToKey(-0.0f), floatToKey(0.0f)); }

TEST(FloatToKey, AgreesWithFloatComparisonOnRandomValues) {
  std::mt19937 rng(1);
  for (int t = 0; t < 200000; ++t) {
    float a, b;
    std::uint32_t ra = rng(), rb = rng();
    std::memcpy(&a, &ra, 4);
    std::memcpy(&b, &rb, 4);
    if (std::isnan(a) || std::isnan(b)) continue;
    EXPECT_EQ(a < b, floatToKey(a) < floatToKey(b));
    EXPECT_EQ(a == b, floatToKey(a) == floatToKey(b));
  }
}

TEST(ToKeys, RejectsNaNNamingTheObjectAndAxis) {
  std::vector<Aabb> boxes = {{{0, 0, 0}, {1, 1, 1}}, {{0, std::nanf(""), 0}, {1, 1, 1}}};
  std::vector<KeyBox> keys;
  try {
    toKeys(boxes, keys);
    FAIL() << "NaN accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), 1u);
    EXPECT_NE(std::string(e.what()).find("object 1: NaN coordinate on axis y"), std::string::npos) << e.what();
  }
}

TEST(ToKeys, RejectsMinAboveMaxNamingTheObjectAndAxis) {
  std::vector<Aabb> boxes = {{{0, 0, 0}, {1, 1, 1}}, {{0, 0, 0}, {1, 1, 1}}, {{0, 0, 2}, {1, 1, 1}}};
  std::vector<KeyBox> keys;
  try {
    toKeys(boxes, keys);
    FAIL() << "min > max accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), 2u);
    EXPECT_NE(std::string(e.what()).find("on axis z"), std::string::npos) << e.what();
  }
}

TEST(ToKeys, AcceptsInfinitiesAndZeroExtent) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<Aabb> boxes = {{{-inf, 0, 5}, {inf, 0, 5}}};
  std::vector<KeyBox> keys;
  ASSERT_NO_THROW(toKeys(boxes, keys));
  // The infinities are the extreme keys of every non-NaN float.
  EXPECT_LT(keys[0].min[0], floatToKey(std::numeric_limits<float>::lowest()));
  EXPECT_GT(keys[0].max[0], floatToKey(std::numeric_limits<float>::max()));
  EXPECT_EQ(keys[0].min[1], keys[0].max[1]);
}

TEST(CheckObjectCount, RejectsMoreObjectsThanIndicesCanAddress) {
  EXPECT_NO_THROW(checkObjectCount(kMaxObjects));
  EXPECT_THROW(checkObjectCount(kMaxObjects + 1), InputError);
}
