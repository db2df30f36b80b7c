#include "all_pairs_kernel.hpp"

#include <bit>
#include <limits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "cpu_features.hpp"

namespace bpaccel {
namespace {

constexpr std::size_t kPad = 8;  // the widest vector, in keys
// Keys as signed integers (sign bit flipped), so SSE2's signed compare works.
// Padding overlaps only a box with keys 0 to 2^32-1 on every axis (the
// KeyBox API lets it through); the loops mask padding lanes off anyway.
constexpr std::int32_t kNever = std::numeric_limits<std::int32_t>::max();
constexpr std::int32_t kNeverMax = std::numeric_limits<std::int32_t>::min();

std::int32_t signedKey(std::uint32_t key) { return static_cast<std::int32_t>(key ^ 0x80000000u); }

void emit(std::uint32_t i, std::size_t j0, unsigned bits, std::vector<Pair>& out) {
  while (bits) {
    out.emplace_back(i, static_cast<std::uint32_t>(j0 + static_cast<std::size_t>(std::countr_zero(bits))));
    bits &= bits - 1;
  }
}

void scalarPairs(const AllPairsKernel::Scratch& s, std::size_t n, std::vector<Pair>& out) {
  const std::int32_t *minX = s.axes[0].data(), *minY = s.axes[1].data(), *minZ = s.axes[2].data();
  const std::int32_t *maxX = s.axes[3].data(), *maxY = s.axes[4].data(), *maxZ = s.axes[5].data();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if ((minX[i] <= maxX[j]) & (minX[j] <= maxX[i]) & (minY[i] <= maxY[j]) & (minY[j] <= maxY[i]) &
          (minZ[i] <= maxZ[j]) & (minZ[j] <= maxZ[i]))
        out.emplace_back(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j));
}

#if defined(__x86_64__)
// Lanes j0 .. j0+3 against box i: a pair is separated when one box's min
// lies above the other's max on some axis.
void sse2Pairs(const AllPairsKernel::Scratch& s, std::size_t n, std::vector<Pair>& out) {
  const std::int32_t* a[6];
  for (int c = 0; c < 6; ++c) a[c] = s.axes[c].data();
  for (std::size_t i = 0; i < n; ++i) {
    __m128i lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
      lo[c] = _mm_set1_epi32(a[c][i]);
      hi[c] = _mm_set1_epi32(a[c + 3][i]);
    }
    const std::size_t first = (i + 1) & ~std::size_t{3};
    for (std::size_t j0 = first; j0 < n; j0 += 4) {
      __m128i apart = _mm_setzero_si128();
      for (int c = 0; c < 3; ++c) {
        const auto minJ = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a[c] + j0));
        const auto maxJ = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a[c + 3] + j0));
        apart = _mm_or_si128(apart, _mm_or_si128(_mm_cmpgt_epi32(lo[c], maxJ), _mm_cmpgt_epi32(minJ, hi[c])));
      }
      unsigned bits = ~static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(apart))) & 0xFu;
      if (j0 <= i) bits &= ~0u << (i + 1 - j0);  // only j > i
      if (n - j0 < 4) bits &= (1u << (n - j0)) - 1;  // only j < n
      emit(static_cast<std::uint32_t>(i), j0, bits, out);
    }
  }
}

__attribute__((target("avx2"))) void avx2Pairs(const AllPairsKernel::Scratch& s, std::size_t n,
                                                std::vector<Pair>& out) {
  const std::int32_t* a[6];
  for (int c = 0; c < 6; ++c) a[c] = s.axes[c].data();
  for (std::size_t i = 0; i < n; ++i) {
    __m256i lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
      lo[c] = _mm256_set1_epi32(a[c][i]);
      hi[c] = _mm256_set1_epi32(a[c + 3][i]);
    }
    const std::size_t first = (i + 1) & ~std::size_t{7};
    for (std::size_t j0 = first; j0 < n; j0 += 8) {
      __m256i apart = _mm256_setzero_si256();
      for (int c = 0; c < 3; ++c) {
        const auto minJ = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a[c] + j0));
        const auto maxJ = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a[c + 3] + j0));
        apart = _mm256_or_si256(apart, _mm256_or_si256(_mm256_cmpgt_epi32(lo[c], maxJ), _mm256_cmpgt_epi32(minJ, hi[c])));
      }
      unsigned bits = ~static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(apart))) & 0xFFu;
      if (j0 <= i) bits &= ~0u << (i + 1 - j0);  // only j > i
      if (n - j0 < 8) bits &= (1u << (n - j0)) - 1;  // only j < n
      emit(static_cast<std::uint32_t>(i), j0, bits, out);
    }
  }
}
#endif

}  // namespace

AllPairsKernel::AllPairsKernel() : AllPairsKernel(scalarPairs, "scalar") {
#if defined(__x86_64__)
  if (cpuHasAvx2()) {
    impl_ = avx2Pairs;
    isa_ = "avx2";
  } else {
    impl_ = sse2Pairs;
    isa_ = "sse2";
  }
#endif
}

AllPairsKernel AllPairsKernel::scalar() { return AllPairsKernel(scalarPairs, "scalar"); }

void AllPairsKernel::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, Scratch& scratch) const {
  const std::size_t n = boxes.size();
  const std::size_t padded = (n + kPad - 1) / kPad * kPad;
  for (int c = 0; c < 6; ++c) scratch.axes[c].resize(padded);
  for (std::size_t t = 0; t < n; ++t)
    for (int c = 0; c < 3; ++c) {
      scratch.axes[c][t] = signedKey(boxes[t].min[c]);
      scratch.axes[c + 3][t] = signedKey(boxes[t].max[c]);
    }
  for (std::size_t t = n; t < padded; ++t)
    for (int c = 0; c < 3; ++c) {
      scratch.axes[c][t] = kNever;
      scratch.axes[c + 3][t] = kNeverMax;
    }
  impl_(scratch, n, out);
}

}  // namespace bpaccel
