#include "keys.hpp"

#include <bit>

#include <fmt/format.h>

namespace bpaccel {

InputError::InputError(std::size_t object, const std::string& reason)
    : std::runtime_error(fmt::format("object {}: {}", object, reason)), object_(object) {}

namespace {

// Everything below works on the integer bits, never on float arithmetic or
// float comparisons: -ffast-math (which many engines build with) lets the
// compiler fold `x + 0.0f` and assume no NaN, which would split the two zeros
// and let NaN through.
constexpr std::uint32_t kSignBit = 0x80000000u;
constexpr std::uint32_t kExponentMask = 0x7F800000u;

std::uint32_t keyOfBits(std::uint32_t bits) {
  // -0.0 becomes +0.0: one key for both zeros.
  bits &= -static_cast<std::uint32_t>(bits != kSignBit);
  // Negative floats order backwards in their bits: flip them all; positives
  // just move above every negative by setting the sign bit. Branch-free.
  const std::uint32_t flip = static_cast<std::uint32_t>(-static_cast<std::int32_t>(bits >> 31)) | kSignBit;
  return bits ^ flip;
}

bool isNaNBits(std::uint32_t bits) { return (bits & ~kSignBit) > kExponentMask; }

}  // namespace

std::uint32_t floatToKey(float value) { return keyOfBits(std::bit_cast<std::uint32_t>(value)); }

void checkObjectCount(std::uint64_t count) {
  if (count > kMaxObjects)
    throw InputError(static_cast<std::size_t>(kMaxObjects),
                     fmt::format("too many objects: {} exceed the 32-bit index limit of {}", count, kMaxObjects));
}

namespace {

// Keys order as the floats do, so min <= max is checked on them.
bool isBad(const Aabb& b, const KeyBox& k) {
  bool nan = false;
  for (int a = 0; a < 3; ++a)
    nan |= static_cast<int>(isNaNBits(std::bit_cast<std::uint32_t>(b.min[a]))) |
           static_cast<int>(isNaNBits(std::bit_cast<std::uint32_t>(b.max[a])));
  // int, not bool, operands: all six compares, branch-free (and no -Wbitwise-instead-of-logical).
  return nan | static_cast<int>(k.min[0] > k.max[0]) | static_cast<int>(k.min[1] > k.max[1]) |
         static_cast<int>(k.min[2] > k.max[2]);
}

[[noreturn]] void throwFirstBad(std::span<const Aabb> boxes, const std::vector<KeyBox>& keys) {
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Aabb& b = boxes[i];
    for (int a = 0; a < 3; ++a) {
      if (isNaNBits(std::bit_cast<std::uint32_t>(b.min[a])) || isNaNBits(std::bit_cast<std::uint32_t>(b.max[a])))
        throw InputError(i, fmt::format("NaN coordinate on axis {}", kAxis[a]));
      if (keys[i].min[a] > keys[i].max[a])
        throw InputError(i, fmt::format("min {} > max {} on axis {}", b.min[a], b.max[a], kAxis[a]));
    }
  }
  throw std::logic_error("toKeys: a bad box was flagged but not found");
}

}  // namespace

void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out) {
  checkObjectCount(boxes.size());
  out.resize(boxes.size());
  // One branch-free pass that converts and only accumulates a flag, so the
  // compiler can vectorise it; the rare bad input is located afterwards.
  bool bad = false;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Aabb& b = boxes[i];
    KeyBox& k = out[i];
    for (int a = 0; a < 3; ++a) {
      k.min[a] = keyOfBits(std::bit_cast<std::uint32_t>(b.min[a]));
      k.max[a] = keyOfBits(std::bit_cast<std::uint32_t>(b.max[a]));
    }
    bad |= isBad(b, k);
  }
  if (bad) [[unlikely]]
    throwFirstBad(boxes, out);
}

}  // namespace bpaccel
