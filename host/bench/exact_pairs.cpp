#include "exact_pairs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace bpaccel {
namespace {

bool overlap(const Aabb& a, const Aabb& b) {
  return a.min[0] <= b.max[0] && b.min[0] <= a.max[0] && a.min[1] <= b.max[1] && b.min[1] <= a.max[1] &&
         a.min[2] <= b.max[2] && b.min[2] <= a.max[2];
}

}  // namespace

void sortAndSweepPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  out.clear();
  std::vector<std::uint32_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return boxes[a].min[0] < boxes[b].min[0]; });
  for (std::size_t s = 0; s < order.size(); ++s) {
    const Aabb& a = boxes[order[s]];
    // Later boxes start at or after a's min x; they overlap on x while they start by a's max x.
    for (std::size_t t = s + 1; t < order.size() && boxes[order[t]].min[0] <= a.max[0]; ++t)
      if (overlap(a, boxes[order[t]])) out.emplace_back(std::min(order[s], order[t]), std::max(order[s], order[t]));
  }
  std::sort(out.begin(), out.end());
}

void exactPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  out.clear();
  const std::size_t n = boxes.size();
  if (n < 2) return;
  // Bounds and the largest extent, in double: every float difference is exact there.
  std::array<double, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  double largest = 0;
  for (const Aabb& b : boxes)
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(b.min[a]) || !std::isfinite(b.max[a])) return sortAndSweepPairs(boxes, out);
      lo[a] = std::min(lo[a], static_cast<double>(b.min[a]));
      hi[a] = std::max(hi[a], static_cast<double>(b.min[a]));
      largest = std::max(largest, static_cast<double>(b.max[a]) - b.min[a]);
    }
  // If b overlaps a and starts after it on an axis, b.min - a.min <= a's extent
  // <= largest < cell: their min corners are in the same or adjacent cells.
  // The margin covers the rounding of (x - lo) / cell, monotonic in x.
  const double span = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const double perAxis = std::max(1.0, std::floor(std::cbrt(2.0 * static_cast<double>(n))));  // ~2 cells a box at most
  double cell = std::max(largest * (1 + 1e-6), span / perAxis);
  if (!(cell > 0)) cell = 1;  // every box is the same point
  std::array<std::uint64_t, 3> dims{};
  for (int a = 0; a < 3; ++a) dims[a] = static_cast<std::uint64_t>((hi[a] - lo[a]) / cell) + 1;
  const auto cellOf = [&](const Aabb& b, int a) {
    return std::min(static_cast<std::uint64_t>((b.min[a] - lo[a]) / cell), dims[a] - 1);
  };
  const auto linear = [&](std::uint64_t x, std::uint64_t y, std::uint64_t z) { return (x * dims[1] + y) * dims[2] + z; };
  const std::uint64_t cells = dims[0] * dims[1] * dims[2];

  // Counting sort of the boxes by cell.
  std::vector<std::uint32_t> start(cells + 1, 0), sorted(n), cellOfBox(n);
  for (std::size_t i = 0; i < n; ++i) {
    cellOfBox[i] = static_cast<std::uint32_t>(linear(cellOf(boxes[i], 0), cellOf(boxes[i], 1), cellOf(boxes[i], 2)));
    ++start[cellOfBox[i] + 1];
  }
  std::partial_sum(start.begin(), start.end(), start.begin());
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) sorted[fill[cellOfBox[i]]++] = static_cast<std::uint32_t>(i);
  }

  // Each cell against itself and its 13 forward neighbours: every pair of
  // neighbouring cells exactly once.
  for (std::uint64_t x = 0; x < dims[0]; ++x)
    for (std::uint64_t y = 0; y < dims[1]; ++y)
      for (std::uint64_t z = 0; z < dims[2]; ++z) {
        const std::uint64_t c = linear(x, y, z);
        for (std::uint32_t s = start[c]; s < start[c + 1]; ++s)
          for (std::uint32_t t = s + 1; t < start[c + 1]; ++t)
            if (overlap(boxes[sorted[s]], boxes[sorted[t]]))
              out.emplace_back(std::min(sorted[s], sorted[t]), std::max(sorted[s], sorted[t]));
        for (int dx = 0; dx <= 1; ++dx)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz) {
              if (dx == 0 && (dy < 0 || (dy == 0 && dz <= 0))) continue;  // backward half and the cell itself
              const std::int64_t nx = static_cast<std::int64_t>(x) + dx, ny = static_cast<std::int64_t>(y) + dy,
                                 nz = static_cast<std::int64_t>(z) + dz;
              if (nx >= static_cast<std::int64_t>(dims[0]) || ny < 0 || ny >= static_cast<std::int64_t>(dims[1]) ||
                  nz < 0 || nz >= static_cast<std::int64_t>(dims[2]))
                continue;
              const std::uint64_t d = linear(static_cast<std::uint64_t>(nx), static_cast<std::uint64_t>(ny),
                                             static_cast<std::uint64_t>(nz));
              for (std::uint32_t s = start[c]; s < start[c + 1]; ++s)
                for (std::uint32_t t = start[d]; t < start[d + 1]; ++t)
                  if (overlap(boxes[sorted[s]], boxes[sorted[t]]))
                    out.emplace_back(std::min(sorted[s], sorted[t]), std::max(sorted[s], sorted[t]));
            }
      }
  std::sort(out.begin(), out.end());
}

}  // namespace bpaccel
