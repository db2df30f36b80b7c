#include "binning_grid.hpp"

#include <algorithm>
#include <bit>
#include <memory>
#include <cmath>
#include <limits>

namespace bpaccel {

namespace {

/// Per axis, a histogram of the finite extents by binary exponent, with each bucket's longest.
struct ExtentHistogram {
  static constexpr int kBuckets = 2047;  // the exponent field of a finite double
  std::array<std::array<std::uint32_t, kBuckets>, 3> count{};
  std::array<std::array<double, kBuckets>, 3> longest{};
  std::size_t finite = 0;
};

int exponentOf(double e) { return static_cast<int>((std::bit_cast<std::uint64_t>(e) >> 52) & 0x7ff); }

}  // namespace

std::array<double, 3> cellEdgeFor(const BinningParams& p, std::span<const Aabb> boxes) {
  auto h = std::make_unique<ExtentHistogram>();
  for (const Aabb& b : boxes)
    for (int a = 0; a < 3; ++a) {
      const double e = double{b.max[a]} - double{b.min[a]};
      const int x = exponentOf(e);
      if (x >= ExtentHistogram::kBuckets) continue;  // infinite or NaN: the host's
      h->count[a][x] += 1;
      h->longest[a][x] = std::max(h->longest[a][x], e);
    }
  const std::size_t outliers = boxes.size() / 256;
  const double keys = std::ldexp(1.0, static_cast<int>(p.maxShift()));
  std::array<double, 3> edge{};
  for (int a = 0; a < 3; ++a) {
    // The bucket of the (outliers + 1)-th longest extent; the buckets more than one above it are outliers.
    std::size_t seen = 0;
    int q = ExtentHistogram::kBuckets - 1;
    for (; q > 0 && seen + h->count[a][q] <= outliers; --q) seen += h->count[a][q];
    double reach = 0;
    for (int x = 0; x <= std::min(q + 1, ExtentHistogram::kBuckets - 1); ++x) reach = std::max(reach, h->longest[a][x]);
    // A box of e spans at most e / unit + 2 keys after the outward rounding; 2^s keys make a cell.
    edge[a] = reach * keys / (keys - 4);
  }
  return edge;
}

KeyGrid pickGrid(const BinningParams& p, std::span<const Aabb> boxes, std::span<const std::uint32_t> ids,
                   const std::array<double, 3>& cellEdge) {
  KeyGrid g;
  g.shift = p.maxShift();
  const double keysPerCell = std::ldexp(1.0, static_cast<int>(g.shift));
  for (int a = 0; a < 3; ++a) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::uint32_t i : ids) lo = std::min(lo, double{boxes[i].min[a]}), hi = std::max(hi, double{boxes[i].max[a]});
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

bool fitsCells(const KeyGrid& grid, const KeyBox& key) {
  for (int a = 0; a < 3; ++a)
    if ((key.max[a] >> grid.shift) - (key.min[a] >> grid.shift) > 1) return false;
  return true;
}

}  // namespace bpaccel
