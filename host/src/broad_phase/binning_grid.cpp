#include "binning_grid.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "../core/cpu_features.hpp"
#include "../core/keys.hpp"
#include "gather.hpp"

namespace bpaccel {

namespace {

int exponentOf(double e) { return static_cast<int>((std::bit_cast<std::uint64_t>(e) >> 52) & 0x7ff); }
constexpr int kNotFinite = 0x7ff;  // the exponent field of an infinite or NaN double

}  // namespace

namespace {

/// A frame's extents in brief: per axis the longest finite extent, the bounds, how many extents are infinite
/// or NaN, and how many lie within the longest one's binary exponent or the one below (its top buckets).
struct ExtentBrief {
  std::array<double, 3> longest{};
  AxisBounds bounds;
  std::array<std::size_t, 3> notFinite{}, top{};
  bool checked = false;  // the vector pass saw every extent >= 0 (no NaN, no min above max)
};

/// The lowest extent of the top buckets: 2^(x - 1) for the longest's binary exponent x; 0 if there is none.
double topFloor(double longest) {
  const int x = exponentOf(longest);
  return x >= 2 ? std::bit_cast<double>(static_cast<std::uint64_t>(x - 1) << 52) : 0.0;
}

void briefScalar(std::span<const Aabb> boxes, std::size_t from, ExtentBrief& brief) {
  for (std::size_t i = from; i < boxes.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const double e = double{boxes[i].max[a]} - double{boxes[i].min[a]};
      const bool finite = exponentOf(e) != kNotFinite;
      brief.longest[a] = std::max(brief.longest[a], finite ? e : 0.0);
      brief.notFinite[a] += !finite;
    }
    brief.bounds.add(boxes[i]);
  }
}

#if defined(__x86_64__)
// The brief's accumulators, four lanes at a time: a box's mins (and its max x) in one vector, its maxes (and
// the next box's min x) in another, so lanes 0-2 are its axes and lane 3 is ignored.
struct BriefLanes {
  __m256d longest, notFinite, suspect, lo, hi;

  __attribute__((target("avx2"))) BriefLanes()
      : longest(_mm256_setzero_pd()), notFinite(_mm256_setzero_pd()), suspect(_mm256_setzero_pd()),
        lo(_mm256_set1_pd(HUGE_VAL)), hi(_mm256_set1_pd(-HUGE_VAL)) {}

  /// Adds one box; returns its extents.
  __attribute__((target("avx2"))) __m256d add(__m256d mins, __m256d maxs) {
    const __m256d e = _mm256_sub_pd(maxs, mins);
    const __m256d finite = _mm256_cmp_pd(e, _mm256_set1_pd(HUGE_VAL), _CMP_LT_OQ);
    longest = _mm256_max_pd(longest, _mm256_and_pd(finite, e));
    notFinite = _mm256_add_pd(notFinite, _mm256_andnot_pd(finite, _mm256_set1_pd(1)));
    // A NaN, or a min above its max (an exact difference of floats is negative then), makes !(e >= 0);
    // so does +inf - +inf, a good box, which checkBoxes then passes.
    suspect = _mm256_or_pd(suspect, _mm256_cmp_pd(e, _mm256_setzero_pd(), _CMP_NGE_UQ));
    lo = _mm256_min_pd(lo, mins), hi = _mm256_max_pd(hi, maxs);
    return e;
  }

  /// Lanes 0-2 into `brief`, whose other boxes they join.
  __attribute__((target("avx2"))) void addTo(ExtentBrief& brief) const {
    brief.checked = (_mm256_movemask_pd(suspect) & 0b111) == 0;
    alignas(32) std::array<double, 4> l, n, b0, b1;
    _mm256_store_pd(l.data(), longest), _mm256_store_pd(n.data(), notFinite);
    _mm256_store_pd(b0.data(), lo), _mm256_store_pd(b1.data(), hi);
    for (int a = 0; a < 3; ++a) {
      brief.longest[a] = std::max(brief.longest[a], l[a]);
      brief.notFinite[a] += static_cast<std::size_t>(n[a]);
      brief.bounds.lo[a] = std::min(brief.bounds.lo[a], b0[a]), brief.bounds.hi[a] = std::max(brief.bounds.hi[a], b1[a]);
    }
  }
};

// The brief's first pass; the last box is left to the scalar loop.
__attribute__((target("avx2"))) std::size_t briefAvx2(std::span<const Aabb> boxes, ExtentBrief& brief) {
  if (boxes.size() < 2) return 0;
  BriefLanes lanes;
  const std::size_t last = boxes.size() - 1;
  for (std::size_t i = 0; i < last; ++i)
    lanes.add(_mm256_cvtps_pd(_mm_loadu_ps(&boxes[i].min[0])), _mm256_cvtps_pd(_mm_loadu_ps(&boxes[i].max[0])));
  lanes.addTo(brief);
  return last;
}

// The second pass: how many extents reach each axis's top floor.
__attribute__((target("avx2"))) std::size_t topAvx2(std::span<const Aabb> boxes, ExtentBrief& brief) {
  if (boxes.size() < 2) return 0;
  const __m256d floor = _mm256_setr_pd(topFloor(brief.longest[0]), topFloor(brief.longest[1]),
                                       topFloor(brief.longest[2]), HUGE_VAL);
  const __m256d one = _mm256_set1_pd(1);
  __m256d top = _mm256_setzero_pd();
  const std::size_t last = boxes.size() - 1;
  for (std::size_t i = 0; i < last; ++i) {
    const __m256d e = _mm256_sub_pd(_mm256_cvtps_pd(_mm_loadu_ps(&boxes[i].max[0])),
                                    _mm256_cvtps_pd(_mm_loadu_ps(&boxes[i].min[0])));
    top = _mm256_add_pd(top, _mm256_and_pd(_mm256_cmp_pd(e, floor, _CMP_GE_OQ), one));
  }
  alignas(32) std::array<double, 4> t;
  _mm256_store_pd(t.data(), top);
  for (int a = 0; a < 3; ++a) brief.top[a] += static_cast<std::size_t>(t[a]);
  return last;
}
#endif

/// Whether the grid's keys fit an int32, as the vector loops' signed conversion needs.
bool keysFitInt32(const KeyGrid& grid) {
  const double int32Keys = 0x7fffffff;
  return grid.top[0] <= int32Keys && grid.top[1] <= int32Keys && grid.top[2] <= int32Keys;
}

/// The survey of a common frame (every extent finite, none an outlier) from its brief.
ExtentSurvey commonSurvey(const BinningParams& p, const ExtentBrief& brief) {
  const double keys = std::ldexp(1.0, static_cast<int>(p.maxShift()));
  ExtentSurvey survey;
  survey.bounds = brief.bounds;
  survey.allWithin = true;
  for (int a = 0; a < 3; ++a) {
    // A box of e spans at most e / unit + 2 keys after the outward rounding; 2^s keys make a cell.
    survey.cellEdge[a] = brief.longest[a] * keys / (keys - 4);
    survey.topFloor[a] = topFloor(brief.longest[a]);
  }
  return survey;
}

/// Whether the brief of n boxes is a common frame's: every extent finite, and more than the outliers (n / 256)
/// in the longest's top buckets, so the (outliers + 1)-th longest is there too and no extent is an outlier.
bool isCommon(const ExtentBrief& brief, std::size_t n) {
  bool common = true;
  for (int a = 0; a < 3; ++a)
    common = common && brief.notFinite[a] == 0 && brief.top[a] > n / 256 && topFloor(brief.longest[a]) > 0;
  return common;
}

#if defined(__x86_64__)
// briefAvx2, topAvx2 on a guessed floor and quantizeAvx2 on contiguous boxes, in one loop (the last box left to
// the caller): returns whether every box's keys fit the cells. A box's keys are stored as two four-key vectors,
// min x, y, z and max x, then max x, y, z and the next box's min x; each store's fourth key is overwritten by
// the next one, so the stores stay within the keys for all but the last box.
__attribute__((target("avx2"))) bool commonPassAvx2(const KeyGrid& g, const std::array<double, 3>& guessedFloor,
                                                    std::span<const Aabb> boxes, ExtentBrief& brief,
                                                    std::span<KeyBox> keys) {
  const __m256d one = _mm256_set1_pd(1), zero = _mm256_setzero_pd();
  const __m256d floor = _mm256_setr_pd(guessedFloor[0], guessedFloor[1], guessedFloor[2], HUGE_VAL);
  const __m256d origin = _mm256_setr_pd(g.origin[0], g.origin[1], g.origin[2], g.origin[0]);
  const __m256d scale = _mm256_setr_pd(g.scale[0], g.scale[1], g.scale[2], g.scale[0]);
  const __m256d top = _mm256_setr_pd(g.top[0], g.top[1], g.top[2], g.top[0]);
  const __m128i shift = _mm_cvtsi32_si128(static_cast<int>(g.shift)), oneKey = _mm_set1_epi32(1);
  const __m128i axes = _mm_setr_epi32(-1, -1, -1, 0);
  BriefLanes lanes;
  __m256d count = zero;
  __m128i wide = _mm_setzero_si128();
  const std::size_t last = boxes.size() - 1;
  for (std::size_t i = 0; i < last; ++i) {
    const __m256d mins = _mm256_cvtps_pd(_mm_loadu_ps(&boxes[i].min[0]));
    const __m256d maxs = _mm256_cvtps_pd(_mm_loadu_ps(&boxes[i].max[0]));
    const __m256d e = lanes.add(mins, maxs);
    count = _mm256_add_pd(count, _mm256_and_pd(_mm256_cmp_pd(e, floor, _CMP_GE_OQ), one));
    // quantize's operations: mins rounded down, maxes up (ceil = floor + (floor < v) on these values).
    const __m256d vMin = _mm256_min_pd(_mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(mins, origin), scale), zero), top);
    const __m256d vMax = _mm256_min_pd(_mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(maxs, origin), scale), zero), top);
    const __m128i low = _mm256_cvttpd_epi32(_mm256_round_pd(vMin, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC));
    const __m128i high = _mm256_cvttpd_epi32(_mm256_round_pd(vMax, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(&keys[i].min[0]), low);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(&keys[i].max[0]), high);
    const __m128i cells = _mm_sub_epi32(_mm_srl_epi32(high, shift), _mm_srl_epi32(low, shift));
    wide = _mm_or_si128(wide, _mm_and_si128(_mm_cmpgt_epi32(cells, oneKey), axes));
  }
  lanes.addTo(brief);
  alignas(32) std::array<double, 4> t;
  _mm256_store_pd(t.data(), count);
  for (int a = 0; a < 3; ++a) brief.top[a] += static_cast<std::size_t>(t[a]);
  return _mm_movemask_epi8(wide) == 0;
}
#endif

/// The brief of boxes from `from` on added to `brief`, then the top buckets' counts of all of them.
void completeBrief(std::span<const Aabb> boxes, std::size_t from, ExtentBrief& brief) {
  std::size_t topFrom = 0;
  briefScalar(boxes, from, brief);
#if defined(__x86_64__)
  if (cpuHasAvx2()) topFrom = topAvx2(boxes, brief);
#endif
  for (std::size_t i = topFrom; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a)
      brief.top[a] += double{boxes[i].max[a]} - double{boxes[i].min[a]} >= topFloor(brief.longest[a]);
}

}  // namespace

ExtentSurvey surveyExtents(const BinningParams& p, std::span<const Aabb> boxes) {
  const std::size_t outliers = boxes.size() / 256;
  const double keys = std::ldexp(1.0, static_cast<int>(p.maxShift()));
  ExtentSurvey survey;
  ExtentBrief brief;
  std::size_t from = 0;
#if defined(__x86_64__)
  if (cpuHasAvx2()) from = briefAvx2(boxes, brief);
#endif
  // The exact check on the bits, naming the first bad box, unless the vector pass saw none (the box it
  // leaves is checked alone).
  if (brief.checked)
    checkBoxes(boxes.subspan(from), from);
  else
    checkBoxes(boxes);
  completeBrief(boxes, from, brief);
  // The common frame, which the brief's two vector passes tell.
  if (isCommon(brief, boxes.size())) return commonSurvey(p, brief);
  // Otherwise per axis a count of the extents by binary exponent, to find the outliers.
  std::array<std::array<std::uint32_t, kNotFinite + 1>, 3> count{};
  for (const Aabb& b : boxes)
    for (int a = 0; a < 3; ++a) count[a][exponentOf(double{b.max[a]} - double{b.min[a]})] += 1;
  survey.bounds = brief.bounds;
  survey.allWithin = true;
  for (int a = 0; a < 3; ++a) {
    // The bucket of the (outliers + 1)-th longest extent; the buckets more than one above it are outliers.
    std::size_t seen = 0;
    int q = kNotFinite - 1;
    for (; q > 0 && seen + count[a][q] <= outliers; --q) seen += count[a][q];
    double reach = brief.longest[a];
    if (exponentOf(reach) > q + 1) {  // outliers: the longest extent below them, in a second pass
      reach = 0;
      for (const Aabb& b : boxes) {
        const double e = double{b.max[a]} - double{b.min[a]};
        reach = std::max(reach, exponentOf(e) <= q + 1 ? e : 0.0);
      }
      survey.allWithin = false;
    }
    survey.allWithin = survey.allWithin && count[a][kNotFinite] == 0;
    survey.cellEdge[a] = reach * keys / (keys - 4);
    survey.topFloor[a] = topFloor(brief.longest[a]);
  }
  return survey;
}

std::optional<CommonPass> surveyCommonOnGrid(const BinningParams& p, std::span<const Aabb> boxes, const KeyGrid& grid,
                                             const std::array<double, 3>& guessedFloor, std::span<KeyBox> keys) {
#if defined(__x86_64__)
  if (!cpuHasAvx2() || boxes.size() < 2 || !keysFitInt32(grid)) return std::nullopt;
  ExtentBrief brief;
  bool keysFit = commonPassAvx2(grid, guessedFloor, boxes, brief, keys);
  // The last box, which the vector loop leaves: a NaN or inverted one is surveyExtents' to name.
  const std::size_t last = boxes.size() - 1;
  const Aabb& b = boxes[last];
  for (int a = 0; a < 3; ++a) {
    const double e = double{b.max[a]} - double{b.min[a]};
    if (!(e >= 0)) return std::nullopt;
    brief.top[a] += e >= guessedFloor[a];
  }
  if (!brief.checked) return std::nullopt;
  briefScalar(boxes, last, brief);
  keys[last] = quantize(grid, b);
  keysFit = keysFit && fitsCells(grid, keys[last]);
  // The top buckets were counted from the guessed floor: they are the frame's only if its longest extents have it.
  for (int a = 0; a < 3; ++a)
    if (topFloor(brief.longest[a]) != guessedFloor[a]) return std::nullopt;
  if (!isCommon(brief, boxes.size())) return std::nullopt;
  return CommonPass{commonSurvey(p, brief), keysFit};
#else
  (void)p, (void)boxes, (void)grid, (void)guessedFloor, (void)keys;
  return std::nullopt;
#endif
}

void AxisBounds::add(const Aabb& b) {
  for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], double{b.min[a]}), hi[a] = std::max(hi[a], double{b.max[a]});
}

KeyGrid gridFor(const BinningParams& p, const AxisBounds& bounds, const std::array<double, 3>& cellEdge) {
  KeyGrid g;
  g.shift = p.maxShift();
  const double keysPerCell = std::ldexp(1.0, static_cast<int>(g.shift));
  for (int a = 0; a < 3; ++a) {
    double lo = bounds.lo[a], hi = bounds.hi[a];
    if (!(hi >= lo)) lo = hi = 0;  // no boxes
    const double range = hi - lo;
    double edge = std::max(range / p.maxDim(), cellEdge[a]);
    if (!(edge > 0) || !std::isfinite(edge)) edge = 1;  // every box flat at one point: one cell
    g.origin[a] = lo;
    g.unit[a] = edge / keysPerCell;
    g.scale[a] = keysPerCell / edge;
    g.dims[a] = static_cast<unsigned>(std::clamp(std::ceil(range / edge), 1.0, double(p.maxDim())));
    g.top[a] = std::min(std::ldexp(static_cast<double>(g.dims[a]), static_cast<int>(g.shift)),
                        std::ldexp(1.0, static_cast<int>(p.keyWidth))) - 1;
  }
  return g;
}

KeyGrid pickGrid(const BinningParams& p, std::span<const Aabb> boxes, std::span<const std::uint32_t> ids,
                 const std::array<double, 3>& cellEdge) {
  AxisBounds bounds;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    prefetchAhead(boxes, ids, k);
    bounds.add(boxes[ids[k]]);
  }
  return gridFor(p, bounds, cellEdge);
}

KeyBox quantize(const KeyGrid& grid, const Aabb& b) {
  KeyBox k;
  for (int a = 0; a < 3; ++a) {
    // Clamped to [0, top] first, so the truncation below rounds down (or, with its fix, up) within the range.
    const double lo = std::clamp((double{b.min[a]} - grid.origin[a]) * grid.scale[a], 0.0, grid.top[a]);
    const double hi = std::clamp((double{b.max[a]} - grid.origin[a]) * grid.scale[a], 0.0, grid.top[a]);
    k.min[a] = static_cast<std::uint32_t>(lo);
    const auto h = static_cast<std::uint32_t>(hi);
    k.max[a] = h + (static_cast<double>(h) < hi);
  }
  return k;
}

namespace {

#if defined(__x86_64__)
// quantize's arithmetic, lane for lane the same IEEE operations (convert, subtract, multiply, clamp, floor;
// a max lane adds one where the floor is below the value), so the keys are the scalar loop's bit for bit:
// min x, y, z and max x in one AVX vector, max y and z in an SSE2 one. Keys must fit an int32 (the
// conversion is signed): the caller checks top. No lambdas: they would not inherit the target attribute.
__attribute__((target("avx2"))) bool quantizeAvx2(const KeyGrid& g, std::span<const Aabb> boxes,
                                                 std::span<const std::uint32_t> ids, std::span<KeyBox> keys) {
  const __m256d origin = _mm256_setr_pd(g.origin[0], g.origin[1], g.origin[2], g.origin[0]);
  const __m256d scale = _mm256_setr_pd(g.scale[0], g.scale[1], g.scale[2], g.scale[0]);
  const __m256d top = _mm256_setr_pd(g.top[0], g.top[1], g.top[2], g.top[0]);
  const __m256d upLane = _mm256_setr_pd(0, 0, 0, 1);  // lane 3 is a max: rounded up
  const __m128d origin2 = _mm_setr_pd(g.origin[1], g.origin[2]), scale2 = _mm_setr_pd(g.scale[1], g.scale[2]);
  const __m128d top2 = _mm_setr_pd(g.top[1], g.top[2]), one2 = _mm_set1_pd(1);
  const __m128i shift = _mm_cvtsi32_si128(static_cast<int>(g.shift)), one = _mm_set1_epi32(1);
  const __m128i axes = _mm_setr_epi32(-1, -1, -1, 0);
  __m128i wide = _mm_setzero_si128();  // lanes where a box spans more than two cells
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const Aabb& b = boxes[ids[k]];
    __m256d v = _mm256_cvtps_pd(_mm_loadu_ps(&b.min[0]));
    v = _mm256_min_pd(_mm256_max_pd(_mm256_mul_pd(_mm256_sub_pd(v, origin), scale), _mm256_setzero_pd()), top);
    const __m256d down = _mm256_round_pd(v, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    const __m256d key = _mm256_add_pd(down, _mm256_and_pd(_mm256_cmp_pd(down, v, _CMP_LT_OQ), upLane));
    const __m128i low = _mm256_cvttpd_epi32(key);  // min x, y, z, max x
    _mm_storeu_si128(reinterpret_cast<__m128i*>(&keys[k].min[0]), low);
    __m128d w = _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(&b.max[1]))));
    w = _mm_min_pd(_mm_max_pd(_mm_mul_pd(_mm_sub_pd(w, origin2), scale2), _mm_setzero_pd()), top2);
    const __m128d down2 = _mm_cvtepi32_pd(_mm_cvttpd_epi32(w));
    const __m128d key2 = _mm_add_pd(down2, _mm_and_pd(_mm_cmplt_pd(down2, w), one2));
    const __m128i high = _mm_cvttpd_epi32(key2);  // max y, z, then zeros
    _mm_storel_epi64(reinterpret_cast<__m128i*>(&keys[k].max[1]), high);
    // fitsCells: (max >> s) - (min >> s) <= 1 on each axis, the maxes being words 3 .. 5 of the six.
    const __m128i cells = _mm_sub_epi32(_mm_srl_epi32(_mm_alignr_epi8(high, low, 12), shift), _mm_srl_epi32(low, shift));
    wide = _mm_or_si128(wide, _mm_and_si128(_mm_cmpgt_epi32(cells, one), axes));
  }
  return _mm_movemask_epi8(wide) == 0;
}
#endif

}  // namespace

bool quantizeAll(const KeyGrid& grid, std::span<const Aabb> boxes, std::span<const std::uint32_t> ids,
                 std::span<KeyBox> keys) {
#if defined(__x86_64__)
  if (cpuHasAvx2() && keysFitInt32(grid))
    return quantizeAvx2(grid, boxes, ids, keys);
#endif
  bool allFit = true;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    keys[k] = quantize(grid, boxes[ids[k]]);
    allFit &= fitsCells(grid, keys[k]);
  }
  return allFit;
}

bool fitsCells(const KeyGrid& grid, const KeyBox& key) {
  for (int a = 0; a < 3; ++a)
    if ((key.max[a] >> grid.shift) - (key.min[a] >> grid.shift) > 1) return false;
  return true;
}

}  // namespace bpaccel
