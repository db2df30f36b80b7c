#include "keys.hpp"

#include <bit>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

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

#if defined(__x86_64__)
// Two boxes (12 words, 3 vectors) a step with SSE2, the baseline of x86-64:
// keyOfBits and isNaNBits lane by lane, and min > max by comparing each min
// word with the word three further on. Returns the index of the first box
// left to the scalar loop; `bad` collects any bad lane.
std::size_t toKeysSse2(std::span<const Aabb> boxes, std::vector<KeyBox>& out, bool& bad) {
  static_assert(sizeof(Aabb) == 24 && sizeof(KeyBox) == 24, "two boxes are three 16-byte vectors");
  const __m128i signBit = _mm_set1_epi32(static_cast<int>(kSignBit));
  const __m128i magnitude = _mm_set1_epi32(static_cast<int>(~kSignBit));
  const __m128i exponent = _mm_set1_epi32(static_cast<int>(kExponentMask));
  // Which lanes hold a min word (its max is three words on): words 0-2 and 6-8 of the 12.
  const __m128i minLanes[3] = {_mm_setr_epi32(-1, -1, -1, 0), _mm_setr_epi32(0, 0, -1, -1), _mm_setr_epi32(-1, 0, 0, 0)};
  const auto key = [&](__m128i bits) {
    bits = _mm_andnot_si128(_mm_cmpeq_epi32(bits, signBit), bits);  // -0.0 becomes +0.0
    return _mm_xor_si128(bits, _mm_or_si128(_mm_srai_epi32(bits, 31), signBit));
  };
  __m128i flags = _mm_setzero_si128();
  const auto* in = reinterpret_cast<const char*>(boxes.data());
  auto* to = reinterpret_cast<char*>(out.data());
  std::size_t i = 0;
  for (; i + 2 <= boxes.size(); i += 2) {
    __m128i w[3], k[3];
    for (int v = 0; v < 3; ++v) {
      w[v] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 24 * i + 16 * v));
      flags = _mm_or_si128(flags, _mm_cmpgt_epi32(_mm_and_si128(w[v], magnitude), exponent));  // NaN
      k[v] = key(w[v]);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(to + 24 * i + 16 * v), k[v]);
    }
    // Words 3-6, 7-10 and 11: the max beside each min lane.
    const __m128i above[3] = {_mm_or_si128(_mm_srli_si128(k[0], 12), _mm_slli_si128(k[1], 4)),
                              _mm_or_si128(_mm_srli_si128(k[1], 12), _mm_slli_si128(k[2], 4)),
                              _mm_srli_si128(k[2], 12)};
    for (int v = 0; v < 3; ++v) {
      // Unsigned min > max as a signed compare with the sign bits flipped.
      const __m128i inverted = _mm_cmpgt_epi32(_mm_xor_si128(k[v], signBit), _mm_xor_si128(above[v], signBit));
      flags = _mm_or_si128(flags, _mm_and_si128(inverted, minLanes[v]));
    }
  }
  bad |= _mm_movemask_epi8(flags) != 0;
  return i;
}
#endif

}  // namespace

void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out) {
  checkObjectCount(boxes.size());
  out.resize(boxes.size());
  // Branch-free passes that convert and only accumulate a flag; the rare bad
  // input is located afterwards.
  bool bad = false;
  std::size_t first = 0;
#if defined(__x86_64__)
  first = toKeysSse2(boxes, out, bad);
#endif
  for (std::size_t i = first; i < boxes.size(); ++i) {
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
