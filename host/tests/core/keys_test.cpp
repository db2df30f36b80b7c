#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <bit>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "core/keys.hpp"

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

// The conversion works on several boxes at once: a bad field is found at
// every position within a group and on every axis, and named.
TEST(ToKeys, RejectsEveryBadFieldAtEveryPositionOfAGroupOfBoxes) {
  // Up to 11: every position of the AVX2 loop's groups of four, the SSE2
  // loop's pair after them and the scalar tail.
  for (std::size_t n = 1; n <= 11; ++n) {
    for (std::size_t at = 0; at < n; ++at) {
      for (int a = 0; a < 3; ++a) {
        for (int kind = 0; kind < 3; ++kind) {  // NaN min, NaN max, min above max
          std::vector<Aabb> boxes(n, Aabb{{-1, -2, -3}, {1, 2, 3}});
          if (kind == 0) boxes[at].min[a] = std::nanf("");
          if (kind == 1) boxes[at].max[a] = -std::nanf("");
          if (kind == 2) boxes[at].min[a] = boxes[at].max[a] + 0.5f;
          std::vector<KeyBox> keys;
          const std::string what = "n " + std::to_string(n) + " box " + std::to_string(at) + " axis " +
                                   std::to_string(a) + " kind " + std::to_string(kind);
          std::string converting;
          try {
            toKeys(boxes, keys);
            ADD_FAILURE() << "accepted: " << what;
          } catch (const InputError& e) {
            EXPECT_EQ(e.object(), at) << what;
            const std::string axis = std::string("axis ") + "xyz"[a];
            EXPECT_NE(std::string(e.what()).find(axis), std::string::npos) << what << ": " << e.what();
            converting = e.what();
          }
          // The check alone refuses the same box with the same words.
          try {
            checkBoxes(boxes);
            ADD_FAILURE() << "checkBoxes accepted: " << what;
          } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()), converting) << what;
          }
        }
      }
    }
  }
  // Many boxes: checkBoxes scans blocks of them branch-free and reads a flagged block again; every block
  // edge, the last partial block, and the first of two bad boxes.
  for (std::size_t at : {0u, 1u, 255u, 256u, 257u, 511u, 512u, 700u, 766u}) {
    std::vector<Aabb> boxes(767, Aabb{{-1, -2, -3}, {1, 2, 3}});
    boxes[at].max[2] = std::nanf("");
    if (at + 300 < boxes.size()) boxes[at + 300].min[0] = 5;
    try {
      checkBoxes(boxes);
      ADD_FAILURE() << "checkBoxes accepted a NaN at " << at;
    } catch (const InputError& e) {
      EXPECT_EQ(e.object(), at);
    }
  }
  // Touching and zero-extent boxes, and -0.0 against +0.0, are fine.
  std::vector<Aabb> good(5, Aabb{{-0.0f, 0, 1}, {0.0f, 0, 1}});
  std::vector<KeyBox> keys;
  EXPECT_NO_THROW(toKeys(good, keys));
  EXPECT_NO_THROW(checkBoxes(good));
  EXPECT_EQ(keys[3].min[0], keys[3].max[0]);
}

TEST(ToKeys, GivesEveryBoxTheKeysOfItsFloatsForEveryCount) {
  // Counts up to 13 cover every way the vector loops (four boxes, then two)
  // and the scalar tail share the boxes; the values include both zeros,
  // infinities and subnormals.
  std::mt19937 rng(11);
  const std::vector<float> special = {0.0f, -0.0f, std::numeric_limits<float>::infinity(),
                                      -std::numeric_limits<float>::infinity(), 1e-40f, -1e-40f,
                                      std::numeric_limits<float>::max(), -std::numeric_limits<float>::max()};
  std::uniform_real_distribution<float> coordinate(-1e4f, 1e4f);
  for (int trial = 0; trial < 40; ++trial)
    for (std::size_t n = 0; n <= 13; ++n) {
      std::vector<Aabb> boxes(n);
      for (Aabb& b : boxes)
        for (int a = 0; a < 3; ++a) {
          float x = rng() % 4 == 0 ? special[rng() % special.size()] : coordinate(rng);
          float y = rng() % 4 == 0 ? special[rng() % special.size()] : coordinate(rng);
          if (floatToKey(y) < floatToKey(x)) std::swap(x, y);
          b.min[a] = x;
          b.max[a] = y;
        }
      std::vector<KeyBox> keys;
      toKeys(boxes, keys);
      ASSERT_EQ(keys.size(), n);
      for (std::size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
          EXPECT_EQ(keys[i].min[a], floatToKey(boxes[i].min[a])) << n << " boxes, box " << i << " axis " << a;
          EXPECT_EQ(keys[i].max[a], floatToKey(boxes[i].max[a])) << n << " boxes, box " << i << " axis " << a;
        }
    }
}

// The bounds found while converting are each axis's lowest min and highest
// max, computed here one box at a time, for every count up to 13 (the
// vector loops' groups and the scalar tail) and for random signs and sizes.
TEST(ToKeys, FindsTheLowestMinAndHighestMaxOfEveryAxisWhileConverting) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-1e6f, 1e6f), size(0.0f, 1e3f);
  for (int trial = 0; trial < 50; ++trial) {
    for (std::size_t n = 0; n <= 13; ++n) {
      std::vector<Aabb> boxes(n);
      for (Aabb& b : boxes)
        for (int a = 0; a < 3; ++a) {
          b.min[a] = coordinate(rng);
          b.max[a] = b.min[a] + size(rng);
        }
      std::vector<KeyBox> keys;
      KeyBounds bounds;
      toKeys(boxes, keys, bounds);
      KeyBounds expected;
      for (const KeyBox& k : keys)
        for (int a = 0; a < 3; ++a) {
          expected.lo[a] = std::min(expected.lo[a], k.min[a]);
          expected.hi[a] = std::max(expected.hi[a], k.max[a]);
        }
      EXPECT_EQ(bounds.lo, expected.lo) << n << " boxes";
      EXPECT_EQ(bounds.hi, expected.hi) << n << " boxes";
      const KeyBounds again = boundsOf(keys);
      EXPECT_EQ(again.lo, expected.lo) << n << " boxes";
      EXPECT_EQ(again.hi, expected.hi) << n << " boxes";
    }
  }
}

namespace {

// The first pair (i < j) that overlaps in `full` but not in `narrow`, or none.
std::optional<std::pair<std::size_t, std::size_t>> missedPair(const std::vector<KeyBox>& full,
                                                              const std::vector<KeyBox>& narrow) {
  for (std::size_t i = 0; i < full.size(); ++i)
    for (std::size_t j = i + 1; j < full.size(); ++j)
      if (overlaps(full[i], full[j]) && !overlaps(narrow[i], narrow[j])) return std::pair{i, j};
  return std::nullopt;
}

// Cells whose keys come from one of several spreads: a few ulps apart, about
// a float's worth of world units, the whole key space, and the extremes.
std::vector<KeyBox> randomCell(std::mt19937& rng, std::size_t n) {
  const std::uint32_t spreads[] = {3, 1u << 12, 1u << 20, 1u << 28, ~0u};
  const std::uint32_t spread = spreads[rng() % std::size(spreads)];
  const std::uint32_t base = spread == ~0u ? 0 : static_cast<std::uint32_t>(rng() % (~0u - 2 * spread));
  std::uniform_int_distribution<std::uint32_t> offset(0, spread), size(0, std::max<std::uint32_t>(spread / 8, 1));
  std::vector<KeyBox> cell(n);
  for (KeyBox& b : cell)
    for (int a = 0; a < 3; ++a) {
      b.min[a] = base + offset(rng);
      if (spread == ~0u && rng() % 4 == 0) b.min[a] = rng() % 2 ? 0u : ~0u;  // the extreme keys
      b.max[a] = static_cast<std::uint32_t>(std::min<std::uint64_t>(std::uint64_t{b.min[a]} + size(rng), ~0u));
    }
  return cell;
}

}  // namespace

// The device may compare fewer bits than the host's keys; narrowing may add
// pairs (the host removes them) but never lose one, and every key fits.
TEST(NarrowKeys, KeepsEveryOverlapAndFitsTheWidth) {
  std::mt19937 rng(11);
  for (const unsigned width : {1u, 2u, 4u, 8u, 16u, 24u, 31u, 32u}) {
    for (int trial = 0; trial < 200; ++trial) {
      const std::vector<KeyBox> cell = randomCell(rng, 1 + rng() % 40);
      std::vector<KeyBox> narrow(cell.size());
      narrowKeys(cell, width, narrow);
      const std::uint64_t top = (std::uint64_t{1} << width) - 1;
      for (const KeyBox& b : narrow)
        for (int a = 0; a < 3; ++a) {
          ASSERT_LE(b.min[a], top) << "width " << width;
          ASSERT_LE(b.max[a], top) << "width " << width;
        }
      const auto missed = missedPair(cell, narrow);
      ASSERT_FALSE(missed) << "width " << width << ": boxes " << missed->first << " and " << missed->second;
    }
  }
}

// Where the cell's keys lie within 2^width of each other nothing is rounded:
// the narrow keys overlap exactly where the full ones do.
TEST(NarrowKeys, IsExactWhereTheCellsRangeFits) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<KeyBox> cell(2 + rng() % 30);
    const std::uint32_t base = rng();
    for (KeyBox& b : cell)
      for (int a = 0; a < 3; ++a) {
        b.min[a] = base / 2 + static_cast<std::uint32_t>(rng() % 40000);
        b.max[a] = b.min[a] + static_cast<std::uint32_t>(rng() % 20000);
      }
    std::vector<KeyBox> narrow(cell.size());
    narrowKeys(cell, 16, narrow);
    for (std::size_t i = 0; i < cell.size(); ++i)
      for (std::size_t j = i + 1; j < cell.size(); ++j)
        ASSERT_EQ(overlaps(cell[i], cell[j]), overlaps(narrow[i], narrow[j])) << "boxes " << i << ", " << j;
  }
}

// The property above can fail: a device port narrower than the keys keeps
// their low bits, which is not monotone, and loses pairs.
TEST(NarrowKeys, TheCheckCatchesKeysCutToTheirLowBits) {
  std::mt19937 rng(13);
  bool caught = false;
  for (int trial = 0; trial < 50 && !caught; ++trial) {
    const std::vector<KeyBox> cell = randomCell(rng, 30);
    std::vector<KeyBox> cut = cell;
    for (KeyBox& b : cut)
      for (int a = 0; a < 3; ++a) {
        b.min[a] &= 0xFFFF;
        b.max[a] &= 0xFFFF;
      }
    caught = missedPair(cell, cut).has_value();
  }
  EXPECT_TRUE(caught);
}

TEST(NarrowKeys, RejectsAWidthOutsideOneToThirtyTwo) {
  const std::vector<KeyBox> cell(2);
  std::vector<KeyBox> out(2);
  EXPECT_THROW(narrowKeys(cell, 0, out), std::invalid_argument);
  EXPECT_THROW(narrowKeys(cell, 33, out), std::invalid_argument);
}

// The SIMD narrowing (where the CPU has AVX2) gives the scalar one's keys for
// every count (groups of four and the tail), boxes with min > max included.
TEST(NarrowKeys, SimdAndScalarGiveTheSameKeysForEveryCount) {
  std::mt19937 rng(14);
  for (int trial = 0; trial < 30; ++trial)
    for (std::size_t n = 0; n <= 13; ++n) {
      std::vector<KeyBox> cell = randomCell(rng, n);
      if (n > 2 && trial % 3 == 0) std::swap(cell[1].min[trial % 3], cell[1].max[trial % 3]);
      for (const unsigned width : {3u, 16u, 32u}) {
        std::vector<KeyBox> fast(n), plain(n);
        narrowKeys(cell, width, fast);
        detail::narrowKeysScalar(cell, width, plain);
        for (std::size_t i = 0; i < n; ++i) {
          ASSERT_EQ(fast[i].min, plain[i].min) << n << " boxes, width " << width << ", box " << i;
          ASSERT_EQ(fast[i].max, plain[i].max) << n << " boxes, width " << width << ", box " << i;
        }
      }
    }
}
