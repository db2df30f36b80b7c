// Built, with host/src/core/keys.cpp, under -ffast-math, as many game engines
// build everything: the key conversion must not depend on float semantics
// that fast-math lets the compiler drop (signed zeros, NaN).

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <vector>

#include "core/keys.hpp"

using namespace bpaccel;

namespace {

// From the bits, so the compiler cannot fold the sign away in this file either.
float fromBits(std::uint32_t bits) { return std::bit_cast<float>(bits); }

}  // namespace

#ifndef __FAST_MATH__
#error "this test must be compiled with -ffast-math"
#endif

TEST(FastMathKeys, BothZerosStillGetOneKey) {
  EXPECT_EQ(floatToKey(fromBits(0x80000000u)), floatToKey(fromBits(0x00000000u)));
}

TEST(FastMathKeys, BoxesTouchingAtZeroStillOverlap) {
  // A ends at -0.0, B starts at +0.0: they touch, so they overlap.
  const std::vector<Aabb> boxes = {{{-1, -1, -1}, {fromBits(0x80000000u), 1, 1}}, {{0.0f, -1, -1}, {1, 1, 1}}};
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  EXPECT_TRUE(overlaps(keys[0], keys[1]));
}

TEST(FastMathKeys, NaNAndMinAboveMaxAreStillRejected) {
  std::vector<KeyBox> keys;
  const std::vector<Aabb> withNaN = {{{0, 0, 0}, {1, 1, 1}}, {{0, 0, fromBits(0x7FC00000u)}, {1, 1, 1}}};
  EXPECT_THROW(toKeys(withNaN, keys), InputError);
  const std::vector<Aabb> inverted = {{{0, 2, 0}, {1, 1, 1}}};
  EXPECT_THROW(toKeys(inverted, keys), InputError);
}
