#include "uniform_grid.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "../core/cpu_features.hpp"
#include "../core/keys.hpp"
#include "../core/thread_pool.hpp"

namespace bpaccel {
namespace {

constexpr std::uint64_t kTop = std::uint64_t{1} << 32;
constexpr std::uint32_t kLowestFinite = 0x00800000u;   // floatToKey(-FLT_MAX)
constexpr std::uint32_t kHighestFinite = 0xFF7FFFFFu;  // floatToKey(FLT_MAX)

// The float of a key (floatToKey's inverse), clamped to the finite floats
// (keys beyond them: the infinities and NaN bit patterns, which the KeyBox
// API lets through).
float finiteValueOf(std::uint32_t key) {
  key = std::clamp(key, kLowestFinite, kHighestFinite);
  return std::bit_cast<float>(key & 0x80000000u ? key & 0x7FFFFFFFu : ~key);
}

// The same as a double; places planes only.
double valueOf(std::uint32_t key) { return static_cast<double>(finiteValueOf(key)); }

// Cells per axis, unrounded, for `target` cells over a scene of `extent`
// (world units per axis).
std::array<double, 3> cellsPerAxis(double target, const std::array<double, 3>& extent) {
  std::array<bool, 3> free{};  // axes whose cell count is still to be chosen
  for (int a = 0; a < 3; ++a) free[a] = extent[a] > 0 && std::isfinite(extent[a]) && target > 1;
  // Cubic cells of edge s = (volume / target)^(1/dims) over the free axes; an
  // axis with less than one such edge (a flat scene) gets one cell and leaves
  // the rest to the others, so the count stays near the target.
  std::array<double, 3> want{1, 1, 1};
  for (bool changed = true; changed;) {
    changed = false;
    double logVolume = 0, fixed = 1;
    int dims = 0;
    for (int a = 0; a < 3; ++a) {
      if (free[a]) {
        logVolume += std::log(extent[a]);
        ++dims;
      } else {
        fixed *= want[a];
      }
    }
    if (dims == 0) break;
    const double logEdge = (logVolume - std::log(std::max(target / fixed, 1.0))) / dims;
    for (int a = 0; a < 3; ++a) {
      if (!free[a]) continue;
      want[a] = std::exp(std::log(extent[a]) - logEdge);
      if (want[a] < 1) {
        want[a] = 1;
        free[a] = false;
        changed = true;
      }
    }
  }
  return want;
}

#if defined(__x86_64__)
// The cell function (see UniformGrid) on four keys, each lane with its own
// axis's constants. Every step is monotone in the key; nothing is NaN: the
// clamped values are finite, so are their halves' differences, and a finite
// product may only round to an infinity, which the clamp to [0, last] takes.
// kAnyKey = false is for keys known to lie in [keyLo, keyHi] of the axis with
// both finite: there both clamps below are the identity (value >= from, so
// value / 2 >= from / 2, both rounded alike), and the result is the same.
template <bool kAnyKey = true>
__m128i cellsOf(__m128i keys, __m128 fromHalf, __m128 scale, __m128 last) {
  const __m128i sign = _mm_set1_epi32(static_cast<int>(0x80000000u));
  __m128i k = _mm_xor_si128(keys, sign);
  if constexpr (kAnyKey) {
    // Keys with the sign bit flipped order as signed integers (SSE2 has only signed compares).
    const __m128i lowest = _mm_set1_epi32(static_cast<int>(kLowestFinite ^ 0x80000000u));
    const __m128i highest = _mm_set1_epi32(static_cast<int>(kHighestFinite ^ 0x80000000u));
    const __m128i below = _mm_cmpgt_epi32(lowest, k);
    k = _mm_or_si128(_mm_and_si128(below, lowest), _mm_andnot_si128(below, k));
    const __m128i above = _mm_cmpgt_epi32(k, highest);
    k = _mm_or_si128(_mm_and_si128(above, highest), _mm_andnot_si128(above, k));
  }
  // floatToKey's inverse on flipped keys: positive floats are k itself,
  // negative ones ~key = k ^ 0x7FFFFFFF.
  const __m128i bits = _mm_xor_si128(k, _mm_and_si128(_mm_srai_epi32(k, 31), _mm_set1_epi32(0x7FFFFFFF)));
  const __m128 value = _mm_castsi128_ps(bits);
  __m128 x = _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(value, _mm_set1_ps(0.5f)), fromHalf), scale);
  if constexpr (kAnyKey) x = _mm_max_ps(x, _mm_setzero_ps());
  return _mm_cvttps_epi32(_mm_min_ps(x, last));
}

// The same on eight keys with AVX2 (the same IEEE single operations in the
// same order, so the same cells). No lambdas below: they would not inherit
// the target attribute.
template <bool kAnyKey>
__attribute__((target("avx2"))) __m256i cellsOfAvx2(__m256i keys, __m256 fromHalf, __m256 scale, __m256 last) {
  const __m256i sign = _mm256_set1_epi32(static_cast<int>(0x80000000u));
  __m256i k = _mm256_xor_si256(keys, sign);
  if constexpr (kAnyKey) {
    k = _mm256_max_epi32(k, _mm256_set1_epi32(static_cast<int>(kLowestFinite ^ 0x80000000u)));
    k = _mm256_min_epi32(k, _mm256_set1_epi32(static_cast<int>(kHighestFinite ^ 0x80000000u)));
  }
  const __m256i bits =
      _mm256_xor_si256(k, _mm256_and_si256(_mm256_srai_epi32(k, 31), _mm256_set1_epi32(0x7FFFFFFF)));
  const __m256 value = _mm256_castsi256_ps(bits);
  __m256 x = _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(value, _mm256_set1_ps(0.5f)), fromHalf), scale);
  if constexpr (kAnyKey) x = _mm256_max_ps(x, _mm256_setzero_ps());
  return _mm256_cvttps_epi32(_mm256_min_ps(x, last));
}

// What the first-cells loop needs of the grid: per lane of the three vectors
// that hold four boxes (lane l of vector v is word 8v + l, axis (8v + l) % 3),
// the cell function's constants and the axis's weight in a cell's index.
struct LaneConstants {
  float fromHalf[24], scale[24], last[24];
  std::uint32_t weight[24];
};

// Every box's first cell and the list of straddlers with their ranges (see
// UniformGrid::countBoxes), four boxes a step: the cells of 24 keys in three
// vectors, packed to 16 bits (a box's six are its Range, in place), and each
// box's first and last cell index as sums of weighted cells: a box straddles
// exactly when they differ (the max's cell is at or above the min's on
// every axis). Returns the first box left to the caller.
template <bool kAnyKey, typename Range>
__attribute__((target("avx2"))) std::size_t firstCellsAvx2(const KeyBox* boxes, std::size_t n,
                                                             const LaneConstants& lc, std::uint64_t* counts,
                                                             std::uint32_t* firsts, std::uint32_t* straddlers,
                                                             Range* ranges, std::size_t& straddlingOut) {
  static_assert(sizeof(Range) == 12, "a box's six cells as 16-bit words");
  __m256 fromHalf[3], scale[3], last[3];
  __m256i weight[3];
  for (int v = 0; v < 3; ++v) {
    fromHalf[v] = _mm256_loadu_ps(lc.fromHalf + 8 * v);
    scale[v] = _mm256_loadu_ps(lc.scale + 8 * v);
    last[v] = _mm256_loadu_ps(lc.last + 8 * v);
    weight[v] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(lc.weight + 8 * v));
  }
  const auto* words = reinterpret_cast<const char*>(boxes);
  std::size_t straddling = straddlingOut, i = 0;
  for (; i + 4 <= n; i += 4) {
    __m256i c[3];
    alignas(32) std::uint32_t w[24];
    alignas(32) std::uint16_t r[32];
    for (int v = 0; v < 3; ++v) {
      const __m256i keys = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(words + 24 * i + 32 * v));
      c[v] = cellsOfAvx2<kAnyKey>(keys, fromHalf[v], scale[v], last[v]);
      _mm256_store_si256(reinterpret_cast<__m256i*>(w + 8 * v), _mm256_mullo_epi32(c[v], weight[v]));
    }
    // Cells are at most kMaxCellsPerAxis - 1: 16 bits hold them. packus
    // packs within 128-bit halves; the permutes put the words back in order.
    _mm256_store_si256(reinterpret_cast<__m256i*>(r),
                       _mm256_permute4x64_epi64(_mm256_packus_epi32(c[0], c[1]), 0xD8));
    _mm256_store_si256(reinterpret_cast<__m256i*>(r + 16),
                       _mm256_permute4x64_epi64(_mm256_packus_epi32(c[2], _mm256_setzero_si256()), 0xD8));
    for (std::size_t b = 0; b < 4; ++b) {
      const std::uint32_t first = w[6 * b] + w[6 * b + 1] + w[6 * b + 2];
      const std::uint32_t lastCell = w[6 * b + 3] + w[6 * b + 4] + w[6 * b + 5];
      firsts[i + b] = first;
      ++counts[first];
      // Appended branch-free: the slot is overwritten unless the box straddles.
      straddlers[straddling] = static_cast<std::uint32_t>(i + b);
      std::memcpy(&ranges[straddling], r + 6 * b, sizeof(Range));
      straddling += static_cast<std::size_t>(first != lastCell);
    }
  }
  straddlingOut = straddling;
  return i;
}

#endif

// Calls f(cell, 1, below) for each cell of r but its first, `below` the
// axes on which that cell lies above r's first (the box's min below it):
// branch-free when r spans at most two cells an axis (boxes smaller than
// cells, nearly every straddler), with f(any number, 0, any) for each of the
// seven neighbours the box misses; else by loops. nx, ny: cells on x and y.
template <typename Range, typename F>
void forEachOtherCell(const Range& r, std::uint64_t nx, std::uint64_t ny, F&& f) {
  const unsigned dx = r.last[0] - r.first[0], dy = r.last[1] - r.first[1], dz = r.last[2] - r.first[2];
  if ((dx | dy | dz) <= 1) {
    const std::uint64_t base = (std::uint64_t{r.first[2]} * ny + r.first[1]) * nx + r.first[0];
    for (unsigned o = 1; o < 8; ++o) {
      const unsigned ox = o & 1, oy = (o >> 1) & 1, oz = o >> 2;
      const unsigned inside = static_cast<unsigned>(ox <= dx) & static_cast<unsigned>(oy <= dy) &
                              static_cast<unsigned>(oz <= dz);
      f(base + ox + oy * nx + oz * nx * ny, inside, o);
    }
    return;
  }
  for (std::uint32_t z = r.first[2]; z <= r.last[2]; ++z)
    for (std::uint32_t y = r.first[1]; y <= r.last[1]; ++y)
      for (std::uint32_t x = r.first[0]; x <= r.last[0]; ++x) {
        const unsigned below = static_cast<unsigned>(x != r.first[0]) | static_cast<unsigned>(y != r.first[1]) << 1 |
                               static_cast<unsigned>(z != r.first[2]) << 2;
        if (below) f((z * ny + y) * nx + x, 1u, below);
      }
}

// Where the first-cells loops write (see UniformGrid::countBoxes): each box's
// first cell, counted, and the straddlers with their ranges. Passed by value
// and the count of straddlers kept in a local, so that the loops' stores to
// the counts are not taken to change them.
template <typename Range>
struct FirstCells {
  std::uint64_t* counts;
  std::uint32_t* firsts;
  std::uint32_t* straddlers;
  Range* ranges;
  std::uint64_t nx, ny;
  // Records box i's cells (`c`: its min's on x, y, z, then its max's) after
  // `straddling` straddlers; returns how many are listed then.
  std::size_t record(std::size_t i, const std::uint32_t* c, std::size_t straddling) const {
    Range r;
    for (int a = 0; a < 3; ++a) {
      r.first[a] = static_cast<std::uint16_t>(c[a]);
      r.last[a] = static_cast<std::uint16_t>(c[a + 3]);
    }
    const auto first = static_cast<std::uint32_t>((r.first[2] * ny + r.first[1]) * nx + r.first[0]);
    firsts[i] = first;
    ++counts[first];
    // Appended branch-free: the slot is overwritten unless the box straddles.
    straddlers[straddling] = static_cast<std::uint32_t>(i);
    ranges[straddling] = r;
    // Bitwise on integers, not on bools: no branch, and no warning from clang.
    return straddling + static_cast<std::size_t>(static_cast<unsigned>(r.first[0] != r.last[0]) |
                                                 static_cast<unsigned>(r.first[1] != r.last[1]) |
                                                 static_cast<unsigned>(r.first[2] != r.last[2]));
  }
};

#if defined(__x86_64__)
// The first cells of as many boxes as the vector loops take: four a step
// with AVX2 where the CPU has it, two a step with SSE2; returns the first box
// left to the caller.
template <typename Axis, typename Range>
std::size_t firstCellsVector(std::span<const KeyBox> boxes, const std::array<Axis, 3>& axes,
                             const FirstCells<Range> out, std::size_t& straddlingOut) {
  std::size_t i = 0, straddling = straddlingOut;
  static_assert(sizeof(KeyBox) == 24, "two boxes are three 16-byte vectors");
  // The lanes' axes: x y z x | y z x y | z x y z.
  __m128 fromHalf[3], scale[3], last[3];
  for (int v = 0; v < 3; ++v) {
    const auto lane = [&](int l) -> const Axis& { return axes[(4 * v + l) % 3]; };
    fromHalf[v] = _mm_setr_ps(lane(0).fromHalf, lane(1).fromHalf, lane(2).fromHalf, lane(3).fromHalf);
    scale[v] = _mm_setr_ps(lane(0).scale, lane(1).scale, lane(2).scale, lane(3).scale);
    last[v] = _mm_setr_ps(lane(0).last, lane(1).last, lane(2).last, lane(3).last);
  }
  // The bench's scenes and any from float boxes without infinities have finite bounds.
  bool finite = true;
  for (const Axis& axis : axes) finite = finite && axis.keyLo >= kLowestFinite && axis.keyHi <= kHighestFinite;
  if (cpuHasAvx2()) {
    LaneConstants lc;
    const std::uint32_t weights[3] = {1, static_cast<std::uint32_t>(out.nx),
                                      static_cast<std::uint32_t>(out.nx * out.ny)};
    for (int l = 0; l < 24; ++l) {
      const Axis& axis = axes[l % 3];
      lc.fromHalf[l] = axis.fromHalf;
      lc.scale[l] = axis.scale;
      lc.last[l] = axis.last;
      lc.weight[l] = weights[l % 3];
    }
    i = finite ? firstCellsAvx2<false>(boxes.data(), boxes.size(), lc, out.counts, out.firsts, out.straddlers,
                                       out.ranges, straddling)
               : firstCellsAvx2<true>(boxes.data(), boxes.size(), lc, out.counts, out.firsts, out.straddlers,
                                      out.ranges, straddling);
  }
  const auto twoAtATime = [&]<bool kAnyKey>() {
    const auto* words = reinterpret_cast<const char*>(boxes.data());
    for (; i + 2 <= boxes.size(); i += 2) {
      alignas(16) std::array<std::uint32_t, 12> c;
      for (int v = 0; v < 3; ++v) {
        const __m128i keys = _mm_loadu_si128(reinterpret_cast<const __m128i*>(words + 24 * i + 16 * v));
        _mm_store_si128(reinterpret_cast<__m128i*>(c.data() + 4 * v),
                        cellsOf<kAnyKey>(keys, fromHalf[v], scale[v], last[v]));
      }
      straddling = out.record(i, c.data(), straddling);
      straddling = out.record(i + 1, c.data() + 6, straddling);
    }
  };
  if (finite)
    twoAtATime.template operator()<false>();
  else
    twoAtATime.template operator()<true>();
  straddlingOut = straddling;
  return i;
}

// A box that spans at most two cells an axis (nearly every straddler) joins
// the neighbours of its first cell that its pattern (bit a: two cells on axis
// a) allows: per pattern, their entries in the order forEachOtherCell gives
// them, as offsets from {first cell, id}; seven 16-byte stores and one add
// each, the unused slots overwritten later. nx, ny: cells on x and y.
struct JoinTable {
  __m128i joins[8][7];
  std::array<unsigned, 8> joined{};
};

template <typename Extra>
JoinTable joinTable(std::uint64_t nx, std::uint64_t ny) {
  static_assert(sizeof(Extra) == 16 && offsetof(Extra, id) == 8 && offsetof(Extra, below) == 12,
                "an entry is {cell, id | below << 32}");
  JoinTable t;
  for (unsigned p = 0; p < 8; ++p) {
    for (__m128i& j : t.joins[p]) j = _mm_setzero_si128();
    for (unsigned o = 1; o < 8; ++o)
      if ((o & ~p) == 0)
        t.joins[p][t.joined[p]++] =
            _mm_set_epi64x(static_cast<long long>(std::uint64_t{o} << 32),
                           static_cast<long long>((o & 1) + ((o >> 1) & 1) * nx + (o >> 2) * nx * ny));
  }
  return t;
}
#endif

}  // namespace

std::uint32_t UniformGrid::Axis::cellOf(std::uint32_t key) const {
#if defined(__x86_64__)
  // The very arithmetic of the vector loop, so planes and boxes agree.
  return static_cast<std::uint32_t>(_mm_cvtsi128_si32(cellsOf(_mm_set1_epi32(static_cast<int>(key)),
                                                               _mm_set1_ps(fromHalf), _mm_set1_ps(scale),
                                                               _mm_set1_ps(last))));
#else
  const float value = finiteValueOf(key);
  return static_cast<std::uint32_t>(std::min(std::max((value * 0.5f - fromHalf) * scale, 0.0f), last));
#endif
}

// `count` cells evenly spaced in world units over [value(lo), value(hi)];
// each plane is the first key the cell function maps to its cell (none: the
// cell's region is empty and it never holds a box).
void UniformGrid::Axis::place(std::uint32_t lo, std::uint32_t hi, std::uint32_t count) {
  keyLo = lo;
  keyHi = hi;
  const double from = valueOf(lo), to = valueOf(hi);
  if (!(to > from)) count = 1;
  fromHalf = static_cast<float>(from * 0.5);
  const double perHalfUnit = count / ((to - from) * 0.5);
  scale = count > 1 ? static_cast<float>(std::min(perHalfUnit, double{std::numeric_limits<float>::max()})) : 0.0f;
  last = static_cast<float>(count - 1);
  planes.assign(1, 0);
  // The plane of c is the first key k with cellOf(k) >= c (kTop: none). A
  // search over all keys from the previous plane took 32 steps a plane
  // (about a tenth of the grid's build at 8000 boxes); here it starts at the
  // key of the plane's value by the inverse of the cell function and gallops
  // out until it has keys on both sides, then halves. Only monotonicity
  // makes the answer right; the estimate only makes the search short.
  const auto atLeast = [&](std::uint64_t k, std::uint32_t c) { return cellOf(static_cast<std::uint32_t>(k)) >= c; };
  for (std::uint32_t c = 1; c < count; ++c) {
    std::uint64_t lo = planes.back(), hi = kTop;  // the plane lies in [lo, hi]; hi is kTop or at least c
    if (lo < kTop) {
      const double guess = std::clamp(2.0 * (c / static_cast<double>(scale) + static_cast<double>(fromHalf)),
                                      -double{std::numeric_limits<float>::max()},
                                      double{std::numeric_limits<float>::max()});
      const std::uint64_t e = std::clamp<std::uint64_t>(floatToKey(static_cast<float>(guess)), lo, kTop - 1);
      if (atLeast(e, c)) {
        hi = e;
        for (std::uint64_t step = 1; e - lo > step; step *= 2) {
          if (!atLeast(e - step, c)) {
            lo = e - step + 1;
            break;
          }
          hi = e - step;
        }
      } else {
        lo = e + 1;
        for (std::uint64_t step = 1; e + step < kTop; step *= 2) {
          if (atLeast(e + step, c)) {
            hi = e + step;
            break;
          }
          lo = e + step + 1;
        }
      }
    }
    while (lo < hi) {
      const std::uint64_t mid = lo + (hi - lo) / 2;
      if (atLeast(mid, c))
        hi = mid;
      else
        lo = mid + 1;
    }
    planes.push_back(lo);
  }
  planes.push_back(kTop);
}

void UniformGrid::chooseResolution(std::span<const KeyBox> boxes, std::size_t cellSize, const KeyBounds& bounds) {
  const std::array<std::uint32_t, 3> hi = bounds.hi, lo = boxes.empty() ? hi : bounds.lo;
  // ceil(2n / cellSize) cells (at most 2n, so memory stays linear in n).
  const double target = std::ceil(2.0 * static_cast<double>(boxes.size()) / static_cast<double>(cellSize));
  std::array<double, 3> extent{};
  for (int a = 0; a < 3; ++a) extent[a] = valueOf(hi[a]) - valueOf(lo[a]);
  const std::array<double, 3> want = cellsPerAxis(target, extent);
  for (int a = 0; a < 3; ++a) {
    const double cells = std::clamp(std::round(want[a]), 1.0, static_cast<double>(kMaxCellsPerAxis));
    axes_[a].place(lo[a], hi[a], static_cast<std::uint32_t>(cells));
  }
}

std::array<std::uint32_t, 3> UniformGrid::resolution() const {
  return {axes_[0].cells(), axes_[1].cells(), axes_[2].cells()};
}

// Every box's first cell (its min corner's) is counted branch-free; boxes
// that straddle a plane (about a third on the bench's scene) are listed and
// their other cells counted after, so the common case has no branch to
// mispredict. The cells of four boxes (24 keys) are computed at a time with
// AVX2 where the CPU has it, of two with SSE2 for the rest. Each part of the
// boxes (one a thread) counts into its own counters.
void UniformGrid::countFirstCells(std::span<const KeyBox> boxes, Part& part) {
  const std::span<const KeyBox> mine = boxes.subspan(part.begin, part.end - part.begin);
  // Grow only: value-initialising the tail again every frame would cost a pass.
  if (part.straddlers.size() < mine.size()) {
    part.straddlers.resize(mine.size());
    part.ranges.resize(mine.size());
  }
  // Locals: the loop's stores cannot be seen to leave the members alone.
  const FirstCells<Range> out{part.firstCounts.data(), firstCell_.data() + part.begin, part.straddlers.data(),
                              part.ranges.data(), axes_[0].cells(), axes_[1].cells()};
  std::size_t i = 0, straddling = 0;
#if defined(__x86_64__)
  i = firstCellsVector(mine, axes_, out, straddling);
#endif
  for (; i < mine.size(); ++i) {
    std::array<std::uint32_t, 6> c;
    for (int a = 0; a < 3; ++a) {
      c[a] = axes_[a].cellOf(mine[i].min[a]);
      c[a + 3] = axes_[a].cellOf(mine[i].max[a]);
    }
    straddling = out.record(i, c.data(), straddling);
  }
  part.straddling = straddling;
}

// The part's straddlers' other cells, listed first (stores to consecutive
// slots, branch-free for nearly all), then counted. False once the part
// alone holds more than `cap` entries (the whole scene's cap: the work
// before a fallback stays bounded, and the decision is the serial one's).
bool UniformGrid::countOtherCells(Part& part, std::uint64_t cap) {
  const std::uint64_t nx = axes_[0].cells(), ny = axes_[1].cells();
  std::uint64_t* const counts = part.extraCounts.data();
  const std::uint32_t* const straddlers = part.straddlers.data();
  const Range* const ranges = part.ranges.data();
  const auto base = static_cast<std::uint32_t>(part.begin);  // straddlers are listed by their place in the part
  std::uint64_t entries = part.end - part.begin;
  std::size_t extra = 0;
  std::vector<Extra>& extras = part.extras;
#if defined(__x86_64__)
  const JoinTable table = joinTable<Extra>(nx, ny);
#endif
  for (std::size_t k = 0; k < part.straddling; ++k) {
    const Range& r = ranges[k];
    const std::uint32_t id = base + straddlers[k];
#if defined(__x86_64__)
    const unsigned dx = r.last[0] - r.first[0], dy = r.last[1] - r.first[1], dz = r.last[2] - r.first[2];
    if ((dx | dy | dz) <= 1) {
      const unsigned p = dx | dy << 1 | dz << 2;
      entries += table.joined[p];
      if (entries > cap) return false;
      if (extras.size() < extra + 7) extras.resize(2 * extra + 16);
      const std::uint64_t first = (std::uint64_t{r.first[2]} * ny + r.first[1]) * nx + r.first[0];
      const __m128i at = _mm_set_epi64x(static_cast<long long>(id), static_cast<long long>(first));
      auto* const slots = reinterpret_cast<__m128i*>(extras.data() + extra);
      for (unsigned j = 0; j < 7; ++j) _mm_storeu_si128(slots + j, _mm_add_epi64(at, table.joins[p][j]));
      extra += table.joined[p];
      continue;
    }
#endif
    const std::uint64_t others = std::uint64_t{r.last[0] - r.first[0] + 1u} * (r.last[1] - r.first[1] + 1u) *
                                     (r.last[2] - r.first[2] + 1u) - 1;
    entries += others;
    if (entries > cap) return false;
    // Room for every slot written, the seven of the branch-free path included.
    if (extras.size() < extra + std::max<std::uint64_t>(others, 7)) extras.resize(2 * (extra + others) + 8);
    Extra* const slots = extras.data();
    forEachOtherCell(r, nx, ny, [&](std::uint64_t cell, unsigned inside, unsigned below) {
      slots[extra] = {cell, id, static_cast<std::uint8_t>(below)};
      extra += inside;
    });
  }
  part.extraCount = extra;
  part.entries = entries;
  for (const Extra& e : std::span<const Extra>(extras).first(extra)) ++counts[e.cell];
  return true;
}

void UniformGrid::build(std::span<const KeyBox> boxes, std::size_t cellSize, const CellSink& onCell,
                        const KeyBounds* bounds) {
  if (!place(boxes, cellSize, bounds, nullptr)) {
    fallback_.build(boxes, cellSize, onCell);
    return;
  }
  gather(boxes, 0, cells_.size());
  if (!onCell) return;
  for (const Cell& cell : cells_)
    onCell(cell, {items_.data() + cell.begin, cell.count}, {packed_.data() + cell.begin, cell.count});
}

void UniformGrid::buildInSteps(std::span<const KeyBox> boxes, std::size_t cellSize, const StepSink& onStep,
                               const KeyBounds* bounds) {
  if (!place(boxes, cellSize, bounds, nullptr)) {
    fallback_.build(boxes, cellSize, {});
    if (onStep) onStep(fallback_.cells().size());
    return;
  }
  const std::size_t perSlab = std::size_t{axes_[0].cells()} * axes_[1].cells();
  for (std::size_t to = perSlab; to <= cells_.size(); to += perSlab) {
    gather(boxes, to - perSlab, to);
    if (onStep) onStep(to);
  }
}

void UniformGrid::buildIndex(std::span<const KeyBox> boxes, std::size_t cellSize, const KeyBounds* bounds,
                             ThreadPool* pool) {
  if (!place(boxes, cellSize, bounds, pool)) fallback_.build(boxes, cellSize, {});
}

bool UniformGrid::place(std::span<const KeyBox> boxes, std::size_t cellSize, const KeyBounds* bounds,
                        ThreadPool* pool) {
  checkObjectCount(boxes.size());
  if (cellSize < 1) cellSize = 1;
  cells_.clear();
  gathered_ = false;
  chooseResolution(boxes, cellSize, bounds ? *bounds : boundsOf(boxes));
  const std::size_t cellCount = std::size_t{axes_[0].cells()} * axes_[1].cells() * axes_[2].cells();
  if (firstCell_.size() < boxes.size()) firstCell_.resize(boxes.size());
  ThreadPool serial(1);
  ThreadPool& threads = pool ? *pool : serial;
  parts_.resize(threads.partsOf(boxes.size()));
  std::vector<char> fits(parts_.size(), 0);
  const std::uint64_t cap = kMaxEntriesPerBox * boxes.size();
  threads.forParts(boxes.size(), [&](std::size_t k, std::size_t begin, std::size_t end) {
    Part& part = parts_[k];
    part.begin = begin;
    part.end = end;
    part.firstCounts.assign(cellCount, 0);
    part.extraCounts.assign(cellCount, 0);
    countFirstCells(boxes, part);
    fits[k] = countOtherCells(part, cap);
  });
  std::uint64_t entries = 0;
  for (std::size_t k = 0; k < parts_.size(); ++k) entries += fits[k] ? parts_[k].entries : cap + 1;
  fellBack_ = entries > cap;
  if (fellBack_) return false;
  const std::uint64_t total = placeCells();
  items_.resize(total);
  itemBelow_.resize(total);
  packed_.resize(total);
  threads.forParts(boxes.size(), [&](std::size_t k, std::size_t, std::size_t) { scatter(parts_[k]); });
  return true;
}

// Each cell's place in the item list: its first cells part by part, then its
// other cells part by part (the order one part alone would give). The
// counters become the parts' cursors.
std::uint64_t UniformGrid::placeCells() {
  const std::uint32_t nx = axes_[0].cells(), ny = axes_[1].cells(), nz = axes_[2].cells();
  std::uint64_t total = 0;
  cells_.reserve(std::size_t{nx} * ny * nz);
  for (std::uint32_t z = 0; z < nz; ++z)
    for (std::uint32_t y = 0; y < ny; ++y)
      for (std::uint32_t x = 0; x < nx; ++x) {
        const std::uint64_t c = (std::uint64_t{z} * ny + y) * nx + x, start = total;
        for (Part& part : parts_) {
          const std::uint64_t count = part.firstCounts[c];
          part.firstCounts[c] = total;
          total += count;
        }
        for (Part& part : parts_) {
          const std::uint64_t count = part.extraCounts[c];
          part.extraCounts[c] = total;
          total += count;
        }
        cells_.push_back({start,
                          static_cast<std::uint32_t>(total - start),
                          {axes_[0].planes[x], axes_[1].planes[y], axes_[2].planes[z]},
                          {axes_[0].planes[x + 1], axes_[1].planes[y + 1], axes_[2].planes[z + 1]}});
      }
  return total;
}

// A part's boxes into their first cells (below no axis there), then its
// straddlers into their others.
void UniformGrid::scatter(Part& part) {
  std::uint64_t* const cursor = part.firstCounts.data();
  std::uint32_t* const items = items_.data();
  std::uint8_t* const below = itemBelow_.data();
  const std::uint32_t* const firsts = firstCell_.data();
  for (std::size_t i = part.begin; i < part.end; ++i) {
    const std::uint64_t at = cursor[firsts[i]]++;
    items[at] = static_cast<std::uint32_t>(i);
    below[at] = 0;
  }
  std::uint64_t* const extraCursor = part.extraCounts.data();
  for (const Extra& e : std::span<const Extra>(part.extras).first(part.extraCount)) {
    const std::uint64_t at = extraCursor[e.cell]++;
    items[at] = e.id;
    below[at] = e.below;
  }
}

// Writing the boxes in order is cheaper than scattering them with their
// indices (one cache line filled at a time).
void UniformGrid::gather(std::span<const KeyBox> boxes, std::size_t from, std::size_t to) {
  gathered_ = true;
  if (from == to) return;
  const std::uint32_t* const items = items_.data();
  KeyBox* const packed = packed_.data();
  const std::uint64_t end = cells_[to - 1].begin + cells_[to - 1].count;
  for (std::uint64_t t = cells_[from].begin; t < end; ++t) packed[t] = boxes[items[t]];
}

}  // namespace bpaccel
