#include "keys.hpp"

#include <algorithm>
#include <array>
#include <bit>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <fmt/format.h>

#include "cpu_features.hpp"
#include "thread_pool.hpp"

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

// The first bad coordinate of box i, named as the user wrote it; on the
// keys, so that -ffast-math cannot fold the checks away.
void checkBox(std::size_t i, const Aabb& b) {
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    const auto lo = std::bit_cast<std::uint32_t>(b.min[a]), hi = std::bit_cast<std::uint32_t>(b.max[a]);
    if (isNaNBits(lo) || isNaNBits(hi)) throw InputError(i, fmt::format("NaN coordinate on axis {}", kAxis[a]));
    if (keyOfBits(lo) > keyOfBits(hi))
      throw InputError(i, fmt::format("min {} > max {} on axis {}", b.min[a], b.max[a], kAxis[a]));
  }
}

[[noreturn]] void throwFirstBad(std::span<const Aabb> boxes) {
  checkBoxes(boxes);
  throw std::logic_error("toKeys: a bad box was flagged but not found");
}

#if defined(__x86_64__)
// The bounds of boxes two at a time (three vectors of keys): each word
// becomes t = key ^ flip, flip being the sign bit for a min word and its
// complement for a max word, so that t in signed order (SSE2 compares only
// signed and has no 32-bit min) orders mins as keys and maxes in reverse; one
// running least per lane then holds the lowest min or the highest max.
class BoundsSse2 {
 public:
  void add(const __m128i (&keys)[3]) {
    for (int v = 0; v < 3; ++v) {
      const __m128i t = _mm_xor_si128(keys[v], flip_[v]);
      const __m128i lower = _mm_cmpgt_epi32(least_[v], t);
      least_[v] = _mm_or_si128(_mm_and_si128(lower, t), _mm_andnot_si128(lower, least_[v]));
    }
  }
  void mergeInto(KeyBounds& bounds) const {
    for (int v = 0; v < 3; ++v) {
      alignas(16) std::array<std::uint32_t, 4> k;
      _mm_store_si128(reinterpret_cast<__m128i*>(k.data()), _mm_xor_si128(least_[v], flip_[v]));
      for (int lane = 0; lane < 4; ++lane) {
        const int word = 4 * v + lane, axis = word % 3;  // words 0-2 and 6-8 of the twelve are mins
        if (word % 6 < 3)
          bounds.lo[axis] = std::min(bounds.lo[axis], k[lane]);
        else
          bounds.hi[axis] = std::max(bounds.hi[axis], k[lane]);
      }
    }
  }

 private:
  static constexpr int kMinFlip = static_cast<int>(kSignBit), kMaxFlip = static_cast<int>(~kSignBit);
  const __m128i flip_[3] = {_mm_setr_epi32(kMinFlip, kMinFlip, kMinFlip, kMaxFlip),
                            _mm_setr_epi32(kMaxFlip, kMaxFlip, kMinFlip, kMinFlip),
                            _mm_setr_epi32(kMinFlip, kMaxFlip, kMaxFlip, kMaxFlip)};
  // Flipped back, the start is ~0 in min lanes and 0 in max lanes: no bound yet.
  __m128i least_[3] = {_mm_set1_epi32(kMaxFlip), _mm_set1_epi32(kMaxFlip), _mm_set1_epi32(kMaxFlip)};
};

// Two boxes (12 words, 3 vectors) a step with SSE2, the baseline of x86-64,
// from box i on: keyOfBits and isNaNBits lane by lane, and min > max by
// comparing each min word with the word three further on. Returns the index
// of the first box left to the scalar loop; `bad` collects any bad lane,
// `bounds` (with kBounds) the keys' bounds. The lanes' bounds are a local,
// so they stay in registers: the stores to `out` could alias anything
// reached by pointer.
template <bool kBounds>
std::size_t toKeysSse2(std::span<const Aabb> boxes, std::span<KeyBox> out, std::size_t i, bool& bad,
                       KeyBounds* bounds) {
  BoundsSse2 lanes;
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
  for (; i + 2 <= boxes.size(); i += 2) {
    __m128i w[3], k[3];
    for (int v = 0; v < 3; ++v) {
      w[v] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 24 * i + 16 * v));
      flags = _mm_or_si128(flags, _mm_cmpgt_epi32(_mm_and_si128(w[v], magnitude), exponent));  // NaN
      k[v] = key(w[v]);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(to + 24 * i + 16 * v), k[v]);
    }
    if constexpr (kBounds) lanes.add(k);
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
  if constexpr (kBounds) lanes.mergeInto(*bounds);
  return i;
}

// The same with AVX2, four boxes (24 words, 3 vectors) a step; the SSE2 loop
// and the scalar one take the rest. A word is a min when its index modulo
// six is below three. The bounds need no flipping here: AVX2 has unsigned
// min and max, run on every lane, and the merge takes each lane's own.
// No lambdas: they would not inherit the target attribute.
__attribute__((target("avx2"))) __m256i keysOfBitsAvx2(__m256i bits) {
  const __m256i signBit = _mm256_set1_epi32(static_cast<int>(kSignBit));
  bits = _mm256_andnot_si256(_mm256_cmpeq_epi32(bits, signBit), bits);  // -0.0 becomes +0.0
  return _mm256_xor_si256(bits, _mm256_or_si256(_mm256_srai_epi32(bits, 31), signBit));
}

// Merges the running bounds of keys taken four boxes (three vectors) at a
// time into `bounds`: lane l of vector v is word 8v + l of the four, axis
// (8v + l) % 3, a min where (8v + l) % 6 < 3; `least` holds the lanes'
// lowest keys (read in min lanes), `most` their highest (read in max lanes).
__attribute__((target("avx2"))) void mergeLanesAvx2(const __m256i (&least)[3], const __m256i (&most)[3],
                                                     KeyBounds& bounds) {
  for (int v = 0; v < 3; ++v) {
    alignas(32) std::array<std::uint32_t, 8> lo, hi;
    _mm256_store_si256(reinterpret_cast<__m256i*>(lo.data()), least[v]);
    _mm256_store_si256(reinterpret_cast<__m256i*>(hi.data()), most[v]);
    for (int lane = 0; lane < 8; ++lane) {
      const int word = 8 * v + lane, axis = word % 3;
      if (word % 6 < 3)
        bounds.lo[axis] = std::min(bounds.lo[axis], lo[lane]);
      else
        bounds.hi[axis] = std::max(bounds.hi[axis], hi[lane]);
    }
  }
}

template <bool kBounds>
__attribute__((target("avx2"))) std::size_t toKeysAvx2(std::span<const Aabb> boxes, std::span<KeyBox> out,
                                                        bool& bad, KeyBounds* bounds) {
  static_assert(sizeof(Aabb) == 24 && sizeof(KeyBox) == 24, "four boxes are three 32-byte vectors");
  const __m256i signBit = _mm256_set1_epi32(static_cast<int>(kSignBit));
  const __m256i magnitude = _mm256_set1_epi32(static_cast<int>(~kSignBit));
  const __m256i exponent = _mm256_set1_epi32(static_cast<int>(kExponentMask));
  // Word 8v + l three words on: lanes 3-7 of vector v, then lanes 0-2 of v + 1.
  const __m256i threeOn = _mm256_setr_epi32(3, 4, 5, 6, 7, 0, 1, 2);
  // Min lanes: words 0-2, 6-7 | 8, 12-14 | 18-20 of the 24.
  const __m256i minLanes[3] = {_mm256_setr_epi32(-1, -1, -1, 0, 0, 0, -1, -1),
                               _mm256_setr_epi32(-1, 0, 0, 0, -1, -1, -1, 0),
                               _mm256_setr_epi32(0, 0, -1, -1, -1, 0, 0, 0)};
  __m256i lowest[3], highest[3];
  for (int v = 0; v < 3; ++v) {
    lowest[v] = _mm256_set1_epi32(-1);
    highest[v] = _mm256_setzero_si256();
  }
  __m256i flags = _mm256_setzero_si256();
  const auto* in = reinterpret_cast<const char*>(boxes.data());
  auto* to = reinterpret_cast<char*>(out.data());
  std::size_t i = 0;
  for (; i + 4 <= boxes.size(); i += 4) {
    __m256i k[3];
    for (int v = 0; v < 3; ++v) {
      const __m256i w = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + 24 * i + 32 * v));
      flags = _mm256_or_si256(flags, _mm256_cmpgt_epi32(_mm256_and_si256(w, magnitude), exponent));  // NaN
      k[v] = keysOfBitsAvx2(w);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(to + 24 * i + 32 * v), k[v]);
      if constexpr (kBounds) {
        lowest[v] = _mm256_min_epu32(lowest[v], k[v]);
        highest[v] = _mm256_max_epu32(highest[v], k[v]);
      }
    }
    for (int v = 0; v < 3; ++v) {
      // Vector 2's min lanes need only its own words.
      const __m256i own = _mm256_permutevar8x32_epi32(k[v], threeOn);
      const __m256i above =
          v < 2 ? _mm256_blend_epi32(own, _mm256_permutevar8x32_epi32(k[v + 1], threeOn), 0xE0) : own;
      // Unsigned min > max as a signed compare with the sign bits flipped.
      const __m256i inverted =
          _mm256_cmpgt_epi32(_mm256_xor_si256(k[v], signBit), _mm256_xor_si256(above, signBit));
      flags = _mm256_or_si256(flags, _mm256_and_si256(inverted, minLanes[v]));
    }
  }
  bad |= _mm256_movemask_epi8(flags) != 0;
  if constexpr (kBounds) mergeLanesAvx2(lowest, highest, *bounds);
  return i;
}

#endif

void addBox(const KeyBox& k, KeyBounds& bounds) {
  for (int a = 0; a < 3; ++a) {
    bounds.lo[a] = std::min(bounds.lo[a], k.min[a]);
    bounds.hi[a] = std::max(bounds.hi[a], k.max[a]);
  }
}

// Converts boxes into out (the same size), with their bounds when `bounds`
// is given (a loop of its own each, so the common call without them pays
// nothing). Branch-free passes that convert and only accumulate a flag;
// returns whether a box was bad (the rare bad input is located afterwards).
bool convertPart(std::span<const Aabb> boxes, std::span<KeyBox> out, KeyBounds* bounds) {
  bool bad = false;
  std::size_t first = 0;
#if defined(__x86_64__)
  if (cpuHasAvx2()) first = bounds ? toKeysAvx2<true>(boxes, out, bad, bounds) : toKeysAvx2<false>(boxes, out, bad, nullptr);
  // The boxes the AVX2 loop left (up to three), or all of them without it.
  first = bounds ? toKeysSse2<true>(boxes, out, first, bad, bounds)
                 : toKeysSse2<false>(boxes, out, first, bad, nullptr);
#endif
  for (std::size_t i = first; i < boxes.size(); ++i) {
    const Aabb& b = boxes[i];
    KeyBox& k = out[i];
    for (int a = 0; a < 3; ++a) {
      k.min[a] = keyOfBits(std::bit_cast<std::uint32_t>(b.min[a]));
      k.max[a] = keyOfBits(std::bit_cast<std::uint32_t>(b.max[a]));
    }
    bad |= isBad(b, k);
    if (bounds) addBox(k, *bounds);
  }
  return bad;
}

void convert(std::span<const Aabb> boxes, std::vector<KeyBox>& out, KeyBounds* bounds) {
  checkObjectCount(boxes.size());
  out.resize(boxes.size());
  if (convertPart(boxes, out, bounds)) [[unlikely]]
    throwFirstBad(boxes);
}

}  // namespace

void checkBoxes(std::span<const Aabb> boxes, std::size_t firstIndex) {
  checkObjectCount(firstIndex + boxes.size());
  // The vector converter's check, a block at a time into keys that stay in the L1 cache and are dropped;
  // a flagged block is read again box by box to name the first bad one.
  std::array<KeyBox, 256> scratch;
  for (std::size_t begin = 0; begin < boxes.size(); begin += scratch.size()) {
    const auto block = boxes.subspan(begin, std::min(scratch.size(), boxes.size() - begin));
    if (convertPart(block, std::span<KeyBox>(scratch).first(block.size()), nullptr)) [[unlikely]]
      for (std::size_t i = 0; i < block.size(); ++i) checkBox(firstIndex + begin + i, block[i]);
  }
}

void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out) { convert(boxes, out, nullptr); }

void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out, KeyBounds& bounds) {
  bounds = {};
  convert(boxes, out, &bounds);
}

void toKeys(std::span<const Aabb> boxes, std::vector<KeyBox>& out, KeyBounds& bounds, ThreadPool& pool) {
  checkObjectCount(boxes.size());
  out.resize(boxes.size());
  const std::size_t parts = pool.partsOf(boxes.size());
  std::vector<KeyBounds> partBounds(parts);
  std::vector<char> partBad(parts, 0);
  pool.forParts(boxes.size(), [&](std::size_t k, std::size_t begin, std::size_t end) {
    partBad[k] = convertPart(boxes.subspan(begin, end - begin), std::span<KeyBox>(out).subspan(begin, end - begin),
                             &partBounds[k]);
  });
  bounds = {};
  bool bad = false;
  for (std::size_t k = 0; k < parts; ++k) {
    bad |= partBad[k] != 0;
    for (int a = 0; a < 3; ++a) {
      bounds.lo[a] = std::min(bounds.lo[a], partBounds[k].lo[a]);
      bounds.hi[a] = std::max(bounds.hi[a], partBounds[k].hi[a]);
    }
  }
  if (bad) [[unlikely]]
    throwFirstBad(boxes);
}

KeyBounds boundsOf(std::span<const KeyBox> boxes) {
  KeyBounds bounds;
  std::size_t i = 0;
#if defined(__x86_64__)
  BoundsSse2 lanes;
  const auto* words = reinterpret_cast<const char*>(boxes.data());
  for (; i + 2 <= boxes.size(); i += 2) {
    __m128i k[3];
    for (int v = 0; v < 3; ++v) k[v] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(words + 24 * i + 16 * v));
    lanes.add(k);
  }
  lanes.mergeInto(bounds);
#endif
  for (; i < boxes.size(); ++i) addBox(boxes[i], bounds);
  return bounds;
}

namespace {

// What narrowKeys does to a key on axis a: clamp into the cell's [lo, hi], then the map.
struct NarrowMap {
  std::array<std::uint32_t, 3> lo{}, hi{}, shift{};
  NarrowMap(const KeyBounds& b, unsigned width) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = b.lo[a];
      hi[a] = std::max(b.hi[a], b.lo[a]);  // all boxes min > max: every key maps to 0
      shift[a] = static_cast<std::uint32_t>(
          std::max(0, static_cast<int>(std::bit_width(hi[a] - lo[a])) - static_cast<int>(width)));
    }
  }
  std::uint32_t operator()(std::uint32_t key, int a) const {
    return (std::clamp(key, lo[a], hi[a]) - lo[a]) >> shift[a];
  }
};

}  // namespace

void detail::narrowKeysScalar(std::span<const KeyBox> cell, unsigned width, std::span<KeyBox> out) {
  const NarrowMap map(boundsOf(cell), width);
  for (std::size_t i = 0; i < cell.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      out[i].min[a] = map(cell[i].min[a], a);
      out[i].max[a] = map(cell[i].max[a], a);
    }
}

namespace {

#if defined(__x86_64__)
// The same with AVX2, four boxes (three vectors) a step, both passes over a
// cell that sits in L1, the lanes laid out as in mergeLanesAvx2. The tail
// box by box. No lambdas: they would not inherit the target attribute.
__attribute__((target("avx2"))) void narrowAvx2(std::span<const KeyBox> cell, unsigned width, std::span<KeyBox> out) {
  const std::size_t n = cell.size(), whole = n / 4 * 4;
  const auto* from = reinterpret_cast<const char*>(cell.data());
  auto* to = reinterpret_cast<char*>(out.data());
  __m256i least[3], most[3];
  for (int v = 0; v < 3; ++v) {
    least[v] = _mm256_set1_epi32(-1);
    most[v] = _mm256_setzero_si256();
  }
  for (std::size_t i = 0; i < whole; i += 4)
    for (int v = 0; v < 3; ++v) {
      const __m256i k = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(from + 24 * i + 32 * v));
      least[v] = _mm256_min_epu32(least[v], k);
      most[v] = _mm256_max_epu32(most[v], k);
    }
  KeyBounds bounds;
  mergeLanesAvx2(least, most, bounds);
  for (std::size_t i = whole; i < n; ++i) addBox(cell[i], bounds);
  const NarrowMap map(bounds, width);
  __m256i lo[3], hi[3], shift[3];
  for (int v = 0; v < 3; ++v) {
    alignas(32) std::uint32_t l[8], h[8], s[8];
    for (int lane = 0; lane < 8; ++lane) {
      const int axis = (8 * v + lane) % 3;
      l[lane] = map.lo[axis];
      h[lane] = map.hi[axis];
      s[lane] = map.shift[axis];
    }
    lo[v] = _mm256_load_si256(reinterpret_cast<const __m256i*>(l));
    hi[v] = _mm256_load_si256(reinterpret_cast<const __m256i*>(h));
    shift[v] = _mm256_load_si256(reinterpret_cast<const __m256i*>(s));
  }
  for (std::size_t i = 0; i < whole; i += 4)
    for (int v = 0; v < 3; ++v) {
      const __m256i k = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(from + 24 * i + 32 * v));
      const __m256i clamped = _mm256_min_epu32(_mm256_max_epu32(k, lo[v]), hi[v]);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(to + 24 * i + 32 * v),
                          _mm256_srlv_epi32(_mm256_sub_epi32(clamped, lo[v]), shift[v]));
    }
  for (std::size_t i = whole; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      out[i].min[a] = map(cell[i].min[a], a);
      out[i].max[a] = map(cell[i].max[a], a);
    }
}
#endif

}  // namespace

void narrowKeys(std::span<const KeyBox> cell, unsigned width, std::span<KeyBox> out) {
  if (width < 1 || width > 32) throw std::invalid_argument(fmt::format("narrowKeys: width {} outside 1..32", width));
  if (out.size() != cell.size())
    throw std::invalid_argument(fmt::format("narrowKeys: {} boxes in, room for {}", cell.size(), out.size()));
  // Each key is clamped into [lowest min, highest max] before the map: a
  // no-op for boxes with min <= max; for a KeyBox caller's box with min > max
  // it keeps the map monotone and in range all the same.
#if defined(__x86_64__)
  static_assert(sizeof(KeyBox) == 24, "four boxes are three 32-byte vectors");
  if (cpuHasAvx2()) return narrowAvx2(cell, width, out);
#endif
  detail::narrowKeysScalar(cell, width, out);
}

}  // namespace bpaccel
