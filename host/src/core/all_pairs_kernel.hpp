#pragma once
// The software all-pairs test inside one cell, with the widest SIMD the CPU has.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "types.hpp"

namespace bpaccel {

/// Appends every overlapping pair (i < j, indices into `boxes`) to `out`, in
/// order of i, then j. The boxes are first transposed into per-axis arrays
/// of signed keys, so one vector compare tests 8 (AVX2) or 4 (SSE2) pairs;
/// the implementation is chosen once, for the CPU this runs on.
class AllPairsKernel {
 public:
  AllPairsKernel();
  /// "avx2", "sse2" or "scalar": what this CPU runs.
  std::string_view isa() const { return isa_; }
  /// Forces the portable scalar code, so tests can compare it with the SIMD one.
  static AllPairsKernel scalar();

  /// Scratch space: one per thread that calls run().
  struct Scratch {
    std::vector<std::int32_t> axes[6];  // min x, y, z, max x, y, z, padded to whole vectors
  };
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, Scratch& scratch) const;

 private:
  using Impl = void (*)(const Scratch&, std::size_t n, std::vector<Pair>& out);
  AllPairsKernel(Impl impl, std::string_view isa) : impl_(impl), isa_(isa) {}
  Impl impl_;
  std::string_view isa_;
};

}  // namespace bpaccel
