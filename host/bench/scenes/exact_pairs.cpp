#include "exact_pairs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>

namespace bpaccel {

void sortAndSweepPairs(std::span<const Aabb> boxes, std::vector<Pair>& out, int axis) {
  out.clear();
  std::vector<std::uint32_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return boxes[a].min[axis] < boxes[b].min[axis]; });
  for (std::size_t s = 0; s < order.size(); ++s) {
    const Aabb& a = boxes[order[s]];
    // Later boxes start at or after a's min; they overlap on the axis while they start by a's max.
    for (std::size_t t = s + 1; t < order.size() && boxes[order[t]].min[axis] <= a.max[axis]; ++t)
      if (overlaps(a, boxes[order[t]])) out.emplace_back(std::min(order[s], order[t]), std::max(order[s], order[t]));
  }
  std::sort(out.begin(), out.end());
}

namespace {

// A uniform grid of cells at least as large as the largest box, each box
// in the cell of its min corner: if b overlaps a and starts after it on an
// axis, b.min - a.min <= a's extent <= largest < cell, so their min corners
// are in the same or adjacent cells.
class MinCornerGrid {
 public:
  explicit MinCornerGrid(std::span<const Aabb> boxes) : boxes_(boxes) {
    const std::size_t n = boxes.size();
    // Bounds and the largest extent, in double: every float difference is exact there.
    lo_ = {INFINITY, INFINITY, INFINITY};
    std::array<double, 3> hi{-INFINITY, -INFINITY, -INFINITY};
    double largest = 0;
    for (const Aabb& b : boxes)
      for (int a = 0; a < 3; ++a) {
        lo_[a] = std::min(lo_[a], static_cast<double>(b.min[a]));
        hi[a] = std::max(hi[a], static_cast<double>(b.min[a]));
        largest = std::max(largest, static_cast<double>(b.max[a]) - b.min[a]);
      }
    // The margin covers the rounding of (x - lo) / cell, monotonic in x.
    const double span = std::max({hi[0] - lo_[0], hi[1] - lo_[1], hi[2] - lo_[2]});
    const double perAxis = std::max(1.0, std::floor(std::cbrt(2.0 * static_cast<double>(n))));  // ~2 cells a box at most
    cell_ = std::max(largest * (1 + 1e-6), span / perAxis);
    if (!(cell_ > 0)) cell_ = 1;  // every box is the same point
    for (int a = 0; a < 3; ++a) dims_[a] = static_cast<std::uint64_t>((hi[a] - lo_[a]) / cell_) + 1;
    // Counting sort of the boxes by cell.
    const std::uint64_t cells = dims_[0] * dims_[1] * dims_[2];
    start_.assign(cells + 1, 0);
    sorted_.resize(n);
    std::vector<std::uint32_t> cellOfBox(n);
    for (std::size_t i = 0; i < n; ++i) {
      cellOfBox[i] = static_cast<std::uint32_t>(linear(cellOf(boxes[i], 0), cellOf(boxes[i], 1), cellOf(boxes[i], 2)));
      ++start_[cellOfBox[i] + 1];
    }
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) sorted_[fill[cellOfBox[i]]++] = static_cast<std::uint32_t>(i);
  }

  /// The pairs of boxes the grid tests: within each cell and across neighbours.
  std::uint64_t tests() const {
    std::uint64_t t = 0;
    forEachCellPair([&](std::uint64_t c, std::uint64_t d) {
      const std::uint64_t nc = start_[c + 1] - start_[c];
      t += c == d ? nc * (nc - 1) / 2 : nc * (start_[d + 1] - start_[d]);
    });
    return t;
  }

  void pairs(std::vector<Pair>& out) const {
    const auto record = [&](std::uint32_t i, std::uint32_t j) {
      if (overlaps(boxes_[i], boxes_[j])) out.emplace_back(std::min(i, j), std::max(i, j));
    };
    forEachCellPair([&](std::uint64_t c, std::uint64_t d) {
      for (std::uint32_t s = start_[c]; s < start_[c + 1]; ++s)
        for (std::uint32_t t = c == d ? s + 1 : start_[d]; t < start_[d + 1]; ++t) record(sorted_[s], sorted_[t]);
    });
  }

 private:
  std::uint64_t cellOf(const Aabb& b, int a) const {
    return std::min(static_cast<std::uint64_t>((b.min[a] - lo_[a]) / cell_), dims_[a] - 1);
  }
  std::uint64_t linear(std::uint64_t x, std::uint64_t y, std::uint64_t z) const {
    return (x * dims_[1] + y) * dims_[2] + z;
  }
  // Each cell with itself and its 13 forward neighbours: every pair of
  // neighbouring cells exactly once.
  template <typename F>
  void forEachCellPair(F&& f) const {
    for (std::uint64_t x = 0; x < dims_[0]; ++x)
      for (std::uint64_t y = 0; y < dims_[1]; ++y)
        for (std::uint64_t z = 0; z < dims_[2]; ++z) {
          const std::uint64_t c = linear(x, y, z);
          if (start_[c] == start_[c + 1]) continue;
          f(c, c);
          for (int dx = 0; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dz = -1; dz <= 1; ++dz) {
                if (dx == 0 && (dy < 0 || (dy == 0 && dz <= 0))) continue;  // backward half and the cell itself
                const std::int64_t nx = static_cast<std::int64_t>(x) + dx, ny = static_cast<std::int64_t>(y) + dy,
                                   nz = static_cast<std::int64_t>(z) + dz;
                if (nx >= static_cast<std::int64_t>(dims_[0]) || ny < 0 || ny >= static_cast<std::int64_t>(dims_[1]) ||
                    nz < 0 || nz >= static_cast<std::int64_t>(dims_[2]))
                  continue;
                f(c, linear(static_cast<std::uint64_t>(nx), static_cast<std::uint64_t>(ny),
                            static_cast<std::uint64_t>(nz)));
              }
        }
  }

  std::span<const Aabb> boxes_;
  std::array<double, 3> lo_{};
  double cell_ = 1;
  std::array<std::uint64_t, 3> dims_{};
  std::vector<std::uint32_t> start_, sorted_;
};

}  // namespace

void exactPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  out.clear();
  if (boxes.size() < 2) return;
  for (const Aabb& b : boxes)
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(b.min[a]) || !std::isfinite(b.max[a])) return sortAndSweepPairs(boxes, out);
  int axis = 0;
  std::uint64_t sweepTests = ~std::uint64_t{0};
  for (int a = 0; a < 3; ++a)
    if (const std::uint64_t t = pairsOverlappingOn(boxes, a); t < sweepTests) {
      sweepTests = t;
      axis = a;
    }
  const MinCornerGrid grid(boxes);
  if (sweepTests < grid.tests()) return sortAndSweepPairs(boxes, out, axis);
  grid.pairs(out);
  std::sort(out.begin(), out.end());
}

std::uint64_t pairsOverlappingOn(std::span<const Aabb> boxes, int axis) {
  std::vector<std::pair<float, float>> xs(boxes.size());  // (min, max) on the axis, sorted by min
  std::transform(boxes.begin(), boxes.end(), xs.begin(),
                 [axis](const Aabb& b) { return std::pair(b.min[axis], b.max[axis]); });
  std::ranges::sort(xs, {}, &std::pair<float, float>::first);
  // Each pair once: counted at the box that comes first in order of min,
  // against every later box whose min is not beyond its max.
  std::uint64_t pairs = 0;
  for (auto it = xs.begin(); it != xs.end(); ++it) {
    const auto end = std::ranges::upper_bound(it + 1, xs.end(), it->second, {}, &std::pair<float, float>::first);
    pairs += static_cast<std::uint64_t>(end - it - 1);
  }
  return pairs;
}

}  // namespace bpaccel
