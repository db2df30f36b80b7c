#pragma once
// The software pair test inside one cell, with the widest SIMD the CPU has:
// all pairs, or a sorted sweep along one axis for large cells.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "types.hpp"

namespace bpaccel {

/// One cell as the host's kernels take it: its boxes, and optionally each
/// box's scene index and below() bits (partition.hpp). A pair is owned by the
/// cell when the two boxes' bits share no axis; without bits every pair is.
struct CellBoxes {
  std::span<const KeyBox> boxes;         // the cell's, in order; or, `indexed`, the scene's
  std::span<const std::uint32_t> ids;    // scene index per box; empty: the box's position in the cell
  std::span<const std::uint8_t> below;   // per box; empty: every pair owned
  bool indexed = false;                  // box k is boxes[ids[k]] (a cell's items in the frame's keys)
  std::size_t size() const { return indexed ? ids.size() : boxes.size(); }
  const KeyBox& operator[](std::size_t k) const { return indexed ? boxes[ids[k]] : boxes[k]; }
};

/// The boxes are first transposed into per-axis arrays of signed keys, so
/// one vector compare tests 8 (AVX2) or 4 (SSE2) pairs; the
/// implementation is chosen once, for the CPU this runs on.
class AllPairsKernel {
 public:
  AllPairsKernel();
  /// "avx2", "sse2" or "scalar": what this CPU runs.
  std::string_view isa() const { return isa_; }
  /// The kernel of one instruction set ("avx2", "sse2", "scalar"),
  /// so tests can compare every path this CPU has; throws
  /// std::invalid_argument for one it lacks or does not know.
  static AllPairsKernel forIsa(std::string_view isa);
  /// The portable scalar code.
  static AllPairsKernel scalar() { return forIsa("scalar"); }

  /// Scratch space: one per thread that calls the kernel.
  struct Scratch {
    std::vector<std::int32_t> axes[6];  // min x, y, z, max x, y, z, padded to whole vectors
    std::vector<std::uint8_t> below;    // the sweep's below() bits, in its order
    std::vector<std::uint32_t> ids;     // each box's scene index, where the cell's own do not serve
    std::vector<std::uint64_t> order;   // the sweep's sort keys
  };

  /// Appends every overlapping pair (i < j, indices into `boxes`) to `out`,
  /// in order of i, then j.
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, Scratch& scratch) const;

  /// Appends the pairs of `cell` the cell owns, as scene indices (smaller
  /// first), by testing all pairs. Any order.
  void allPairs(const CellBoxes& cell, std::vector<Pair>& out, Scratch& scratch) const;
  /// The same pairs by a sweep: the boxes sorted by their min on the axis
  /// along which they overlap least (estimated from their spread and
  /// extents), each tested only against those that start before it ends
  /// there, a vector at a time. Worth its sort on large cells only.
  void sweep(const CellBoxes& cell, std::vector<Pair>& out, Scratch& scratch) const;
  /// allPairs up to kSweepAbove boxes, sweep above.
  void ownedPairs(const CellBoxes& cell, std::vector<Pair>& out, Scratch& scratch) const {
    if (cell.size() > kSweepAbove)
      sweep(cell, out, scratch);
    else
      allPairs(cell, out, scratch);
  }
  /// Cells of more boxes are swept (measured: see docs/host.md, "The cpu backend").
  static constexpr std::size_t kSweepAbove = 96;

  struct Impl;  // the loops of one instruction set

 private:
  explicit AllPairsKernel(const Impl* impl) : impl_(impl) {}
  const Impl* impl_;
  std::string_view isa_;
};

}  // namespace bpaccel
