#include "all_pairs_kernel.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "cpu_features.hpp"

namespace bpaccel {
namespace {

using Scratch = AllPairsKernel::Scratch;

constexpr std::size_t kPad = 8;  // the widest vector, in keys
// Keys as signed integers (sign bit flipped), so SSE2's signed compare works.
// Padding overlaps only a box with keys 0 to 2^32-1 on every axis (the
// KeyBox API lets it through); the loops mask padding lanes off anyway.
constexpr std::int32_t kNever = std::numeric_limits<std::int32_t>::max();
constexpr std::int32_t kNeverMax = std::numeric_limits<std::int32_t>::min();

std::int32_t signedKey(std::uint32_t key) { return static_cast<std::int32_t>(key ^ 0x80000000u); }

// Pairs written without a capacity check each: room for a group's worth is
// made before each group, a chunk at a time. Only the chunk is zeroed: the
// sink gives back what it did not use, so growing to twice the vector's size
// would zero the whole vector again for every cell of a batch.
class PairSink {
 public:
  explicit PairSink(std::vector<Pair>& out) : out_(out), used_(out.size()) {}
  PairSink(const PairSink&) = delete;
  PairSink& operator=(const PairSink&) = delete;
  ~PairSink() { out_.resize(used_); }
  Pair* room(std::size_t k) {
    if (out_.size() - used_ < k) out_.resize(used_ + std::max(k, kChunk));
    return out_.data() + used_;
  }
  void advance(const Pair* to) { used_ = static_cast<std::size_t>(to - out_.data()); }

 private:
  static constexpr std::size_t kChunk = 64;
  std::vector<Pair>& out_;
  std::size_t used_;
};

// What a loop needs of its cell: the transposed keys, each box's scene index
// and, where the cell has them, its below() bits: a pair is written with the
// smaller index first and kept where the bits share no axis (no branch).
struct Rows {
  const std::int32_t* axes[6];
  const std::uint32_t* ids;
  const std::uint8_t* below;  // null: every pair kept
  std::size_t n;
  bool owned(std::size_t i, std::size_t j) const { return !below || (below[i] & below[j]) == 0; }
  void emit(PairSink& out, std::size_t i, std::size_t j0, unsigned bits) const {
    Pair* to = out.room(8);
    const std::uint32_t a = ids[i];
    if (below) {
      const unsigned bi = below[i];
      while (bits) {
        const std::size_t j = j0 + static_cast<std::size_t>(std::countr_zero(bits));
        const std::uint32_t b = ids[j];
        *to = {std::min(a, b), std::max(a, b)};
        to += (bi & below[j]) == 0;
        bits &= bits - 1;
      }
    } else {
      while (bits) {
        const std::uint32_t b = ids[j0 + static_cast<std::size_t>(std::countr_zero(bits))];
        *to++ = {std::min(a, b), std::max(a, b)};
        bits &= bits - 1;
      }
    }
    out.advance(to);
  }
};

// Lanes j0 .. j0+w-1 that may pair with box i: only j > i and j < n.
unsigned laneMask(std::size_t i, std::size_t j0, std::size_t n, unsigned w) {
  unsigned bits = (1u << w) - 1;
  if (j0 <= i) bits &= ~0u << (i + 1 - j0);
  if (n - j0 < w) bits &= (1u << (n - j0)) - 1;
  return bits;
}

// The plain loops: the reference the vector ones must match.
bool scalarOverlap(const Rows& r, std::size_t i, std::size_t j) {
  const auto& a = r.axes;
  return (a[0][i] <= a[3][j]) & (a[0][j] <= a[3][i]) & (a[1][i] <= a[4][j]) & (a[1][j] <= a[4][i]) &
         (a[2][i] <= a[5][j]) & (a[2][j] <= a[5][i]);
}

void scalarAll(const Rows& r, PairSink& out) {
  for (std::size_t i = 0; i < r.n; ++i)
    for (std::size_t j = i + 1; j < r.n; ++j)
      if (scalarOverlap(r, i, j)) r.emit(out, i, j, 1);
}

void scalarSweep(const Rows& r, int axis, PairSink& out) {
  for (std::size_t i = 0; i < r.n; ++i)
    for (std::size_t j = i + 1; j < r.n && r.axes[axis][j] <= r.axes[axis + 3][i]; ++j)
      if (scalarOverlap(r, i, j)) r.emit(out, i, j, 1);
}

#if defined(__x86_64__)
// Box i against lanes from `first` on, four at a time, while `more` says so:
// a pair is apart when one box's min lies above the other's max on some axis.
template <typename More>
void sse2Row(const Rows& r, std::size_t i, std::size_t first, PairSink& out, More&& more) {
  __m128i lo[3], hi[3];
  for (int c = 0; c < 3; ++c) {
    lo[c] = _mm_set1_epi32(r.axes[c][i]);
    hi[c] = _mm_set1_epi32(r.axes[c + 3][i]);
  }
  for (std::size_t j0 = first; j0 < r.n && more(j0); j0 += 4) {
    __m128i apart = _mm_setzero_si128();
    for (int c = 0; c < 3; ++c) {
      const auto minJ = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r.axes[c] + j0));
      const auto maxJ = _mm_loadu_si128(reinterpret_cast<const __m128i*>(r.axes[c + 3] + j0));
      apart = _mm_or_si128(apart, _mm_or_si128(_mm_cmpgt_epi32(lo[c], maxJ), _mm_cmpgt_epi32(minJ, hi[c])));
    }
    const unsigned bits = ~static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(apart))) & laneMask(i, j0, r.n, 4);
    if (bits) r.emit(out, i, j0, bits);
  }
}

void sse2All(const Rows& r, PairSink& out) {
  for (std::size_t i = 0; i < r.n; ++i) sse2Row(r, i, (i + 1) & ~std::size_t{3}, out, [](std::size_t) { return true; });
}

void sse2Sweep(const Rows& r, int axis, PairSink& out) {
  const std::int32_t *mins = r.axes[axis], *maxs = r.axes[axis + 3];
  for (std::size_t i = 0; i < r.n; ++i) {
    const std::int32_t end = maxs[i];
    sse2Row(r, i, i + 1, out, [mins, end](std::size_t j0) { return mins[j0] <= end; });
  }
}

// The same with AVX2, eight lanes. (AVX-512's sixteen were measured no
// faster on this machine's cores, which split them in two.)
template <typename More>
__attribute__((target("avx2"))) void avx2Row(const Rows& r, std::size_t i, std::size_t first, PairSink& out,
                                              More&& more) {
  __m256i lo[3], hi[3];
  for (int c = 0; c < 3; ++c) {
    lo[c] = _mm256_set1_epi32(r.axes[c][i]);
    hi[c] = _mm256_set1_epi32(r.axes[c + 3][i]);
  }
  for (std::size_t j0 = first; j0 < r.n && more(j0); j0 += 8) {
    __m256i apart = _mm256_setzero_si256();
    for (int c = 0; c < 3; ++c) {
      const auto minJ = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r.axes[c] + j0));
      const auto maxJ = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r.axes[c + 3] + j0));
      apart = _mm256_or_si256(apart, _mm256_or_si256(_mm256_cmpgt_epi32(lo[c], maxJ), _mm256_cmpgt_epi32(minJ, hi[c])));
    }
    const unsigned bits =
        ~static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(apart))) & laneMask(i, j0, r.n, 8);
    if (bits) r.emit(out, i, j0, bits);
  }
}

__attribute__((target("avx2"))) void avx2All(const Rows& r, PairSink& out) {
  for (std::size_t i = 0; i < r.n; ++i) avx2Row(r, i, (i + 1) & ~std::size_t{7}, out, [](std::size_t) { return true; });
}

__attribute__((target("avx2"))) void avx2Sweep(const Rows& r, int axis, PairSink& out) {
  const std::int32_t *mins = r.axes[axis], *maxs = r.axes[axis + 3];
  for (std::size_t i = 0; i < r.n; ++i) {
    const std::int32_t end = maxs[i];
    avx2Row(r, i, i + 1, out, [mins, end](std::size_t j0) { return mins[j0] <= end; });
  }
}
#endif

// The float of a key (floatToKey's inverse), for the sweep's choice of axis only.
float valueOf(std::uint32_t key) { return std::bit_cast<float>(key & 0x80000000u ? key & 0x7FFFFFFFu : ~key); }

// The axis along which the cell's boxes overlap least, estimated: their mean
// extent against the spread of their mins (a guess; any axis gives the same pairs).
int sweepAxis(const CellBoxes& cell) {
  int best = 0;
  double bestRatio = INFINITY;
  for (int a = 0; a < 3; ++a) {
    double extent = 0, lo = INFINITY, hi = -INFINITY;
    for (std::size_t k = 0; k < cell.size(); ++k) {
      const KeyBox& b = cell[k];
      const double mn = valueOf(b.min[a]), mx = valueOf(b.max[a]);
      extent += mx - mn;
      lo = std::min(lo, mn);
      hi = std::max(hi, mn);
    }
    const double mean = extent / static_cast<double>(cell.size());
    double ratio = mean / (hi - lo + mean);
    if (!std::isfinite(ratio)) ratio = 1;  // points all at one place, or infinite boxes
    if (ratio < bestRatio) {
      bestRatio = ratio;
      best = a;
    }
  }
  return best;
}

// The cell's keys into the scratch's arrays, box k at position k or, with
// `order`, at its position there (its index and bits permuted alike), padded
// with boxes that overlap nothing a whole vector beyond any start.
Rows load(const CellBoxes& cell, Scratch& s, const std::uint64_t* order) {
  const std::size_t n = cell.size();
  const std::size_t padded = (n + 2 * kPad - 1) / kPad * kPad;
  for (auto& axis : s.axes) axis.resize(padded);
  for (std::size_t t = 0; t < n; ++t) {
    const KeyBox& b = cell[order ? static_cast<std::size_t>(order[t] & 0xFFFFFFFFu) : t];
    for (int c = 0; c < 3; ++c) {
      s.axes[c][t] = signedKey(b.min[c]);
      s.axes[c + 3][t] = signedKey(b.max[c]);
    }
  }
  for (std::size_t t = n; t < padded; ++t)
    for (int c = 0; c < 3; ++c) {
      s.axes[c][t] = kNever;
      s.axes[c + 3][t] = kNeverMax;
    }
  Rows r{{}, cell.ids.data(), cell.below.empty() ? nullptr : cell.below.data(), n};
  for (int c = 0; c < 6; ++c) r.axes[c] = s.axes[c].data();
  if (order || cell.ids.empty()) {
    s.ids.resize(n);
    for (std::size_t t = 0; t < n; ++t) {
      const auto k = order ? static_cast<std::uint32_t>(order[t]) : static_cast<std::uint32_t>(t);
      s.ids[t] = cell.ids.empty() ? k : cell.ids[k];
    }
    r.ids = s.ids.data();
  }
  if (order && r.below) {
    s.below.resize(n);
    for (std::size_t t = 0; t < n; ++t) s.below[t] = cell.below[static_cast<std::uint32_t>(order[t])];
    r.below = s.below.data();
  }
  return r;
}

}  // namespace

struct AllPairsKernel::Impl {
  std::string_view isa;
  void (*all)(const Rows&, PairSink&);
  void (*sweep)(const Rows&, int, PairSink&);
};

namespace {

constexpr AllPairsKernel::Impl kScalar{"scalar", scalarAll, scalarSweep};
#if defined(__x86_64__)
constexpr AllPairsKernel::Impl kSse2{"sse2", sse2All, sse2Sweep};
constexpr AllPairsKernel::Impl kAvx2{"avx2", avx2All, avx2Sweep};
#endif

}  // namespace

AllPairsKernel::AllPairsKernel() : AllPairsKernel(&kScalar) {
#if defined(__x86_64__)
  impl_ = cpuHasAvx2() ? &kAvx2 : &kSse2;
#endif
  isa_ = impl_->isa;
}

AllPairsKernel AllPairsKernel::forIsa(std::string_view isa) {
  const Impl* impl = nullptr;
  if (isa == "scalar") impl = &kScalar;
#if defined(__x86_64__)
  if (isa == "sse2") impl = &kSse2;
  if (isa == "avx2" && cpuHasAvx2()) impl = &kAvx2;
#endif
  if (!impl) throw std::invalid_argument("all-pairs kernel: no '" + std::string(isa) + "' loops on this CPU");
  AllPairsKernel k(impl);
  k.isa_ = impl->isa;
  return k;
}

void AllPairsKernel::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, Scratch& scratch) const {
  // Without ids and bits: every pair, as positions in the cell, in order of i then j.
  allPairs({boxes, {}, {}}, out, scratch);
}

void AllPairsKernel::allPairs(const CellBoxes& cell, std::vector<Pair>& out, Scratch& scratch) const {
  const Rows rows = load(cell, scratch, nullptr);
  PairSink sink(out);
  impl_->all(rows, sink);
}

void AllPairsKernel::sweep(const CellBoxes& cell, std::vector<Pair>& out, Scratch& scratch) const {
  const std::size_t n = cell.size();
  if (n < 2) return;
  const int axis = sweepAxis(cell);
  scratch.order.resize(n);
  for (std::size_t k = 0; k < n; ++k) scratch.order[k] = std::uint64_t{cell[k].min[axis]} << 32 | k;
  std::sort(scratch.order.begin(), scratch.order.end());
  const Rows rows = load(cell, scratch, scratch.order.data());
  PairSink sink(out);
  impl_->sweep(rows, axis, sink);
}

}  // namespace bpaccel
