#include "uniform_grid.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "keys.hpp"

namespace bpaccel {
namespace {

constexpr std::uint64_t kTop = std::uint64_t{1} << 32;

// The float of a key (floatToKey's inverse) as a double, clamped to the
// finite floats (keys beyond them: the infinities and NaN bit patterns, which
// the KeyBox API lets through). Places planes only.
double valueOf(std::uint32_t key) {
  constexpr std::uint32_t kLowestFinite = 0x00800000u;   // floatToKey(-FLT_MAX)
  constexpr std::uint32_t kHighestFinite = 0xFF7FFFFFu;  // floatToKey(FLT_MAX)
  key = std::clamp(key, kLowestFinite, kHighestFinite);
  return static_cast<double>(std::bit_cast<float>(key & 0x80000000u ? key & 0x7FFFFFFFu : ~key));
}

}  // namespace

// `count` cells evenly spaced in world units over [value(lo), value(hi)],
// each plane rounded up to a bucket boundary (a cell narrower than a bucket
// may get no key at all: its region is empty and it never holds a box).
void UniformGrid::Axis::place(std::uint32_t lo, std::uint32_t hi, std::uint32_t count) {
  keyLo = lo;
  const double from = valueOf(lo), to = valueOf(hi);
  if (!(to > from)) count = 1;
  const double width = (to - from) / count;
  // A key step at magnitude 2^e is 2^(e - 23) world units (an octave holds
  // 2^23 keys), largest at the scene's largest magnitude: make a bucket
  // there an eighth of a cell, within kMaxBuckets.
  shift = 32;
  if (count > 1) {
    const double top = std::max({std::fabs(from), std::fabs(to), double{std::numeric_limits<float>::min()}});
    const double want = std::floor(std::log2(width / 8) + 23 - std::ilogb(top));
    shift = static_cast<unsigned>(std::clamp(want, 0.0, 32.0));
  }
  while (shift < 32 && (std::uint64_t{hi - lo} >> shift) >= kMaxBuckets) ++shift;
  const std::uint64_t buckets = (std::uint64_t{hi - lo} >> shift) + 1;
  table.resize(buckets);
  planes.assign(1, 0);
  std::uint64_t first = 0;  // the current cell's first bucket
  for (std::uint32_t c = 1; c <= count; ++c) {
    std::uint64_t next = buckets;  // the next cell's first bucket
    if (c < count) {
      const std::uint32_t plane = floatToKey(static_cast<float>(from + width * c));
      const std::uint64_t above = plane > lo ? plane - lo : 0;
      next = std::clamp((above + (std::uint64_t{1} << shift) - 1) >> shift, first, buckets);
    }
    std::fill(table.begin() + static_cast<std::ptrdiff_t>(first), table.begin() + static_cast<std::ptrdiff_t>(next),
              static_cast<std::uint16_t>(c - 1));
    planes.push_back(c < count ? std::min(lo + (next << shift), kTop) : kTop);
    first = next;
  }
}

void UniformGrid::chooseResolution(std::span<const KeyBox> boxes, std::size_t cellSize) {
  std::array<std::uint32_t, 3> lo{~0u, ~0u, ~0u}, hi{0, 0, 0};
  for (const KeyBox& b : boxes)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], b.min[a]);
      hi[a] = std::max(hi[a], b.max[a]);
    }
  if (boxes.empty()) lo = hi;
  // ceil(2n / cellSize) cells (at most 2n, so memory stays linear in n).
  const double target = std::ceil(2.0 * static_cast<double>(boxes.size()) / static_cast<double>(cellSize));
  std::array<double, 3> extent{};
  std::array<bool, 3> free{};  // axes whose cell count is still to be chosen
  for (int a = 0; a < 3; ++a) {
    extent[a] = valueOf(hi[a]) - valueOf(lo[a]);
    free[a] = extent[a] > 0 && std::isfinite(extent[a]) && target > 1;
  }
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
// mispredict.
bool UniformGrid::countBoxes(std::span<const KeyBox> boxes) {
  const std::uint64_t nx = axes_[0].cells(), ny = axes_[1].cells();
  // Grow only: value-initialising the tail again every frame would cost a pass.
  if (firstCell_.size() < boxes.size()) {
    firstCell_.resize(boxes.size());
    straddlers_.resize(boxes.size());
    straddlerRanges_.resize(boxes.size());
  }
  // Locals: the loop's stores cannot be seen to leave the tables alone.
  const std::array<Axis::Lookup, 3> look{axes_[0].lookup(), axes_[1].lookup(), axes_[2].lookup()};
  std::uint64_t* const counts = offsets_.data();
  std::uint32_t* const firsts = firstCell_.data();
  std::uint32_t* const straddlers = straddlers_.data();
  Range* const ranges = straddlerRanges_.data();
  std::size_t straddling = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const KeyBox& b = boxes[i];
    Range r;
    for (int a = 0; a < 3; ++a) {
      r.first[a] = look[a].cellOf(b.min[a]);
      r.last[a] = look[a].cellOf(b.max[a]);
    }
    const auto first = static_cast<std::uint32_t>((r.first[2] * ny + r.first[1]) * nx + r.first[0]);
    firsts[i] = first;
    ++counts[first];
    // Appended branch-free: the slot is overwritten unless the box straddles.
    straddlers[straddling] = static_cast<std::uint32_t>(i);
    ranges[straddling] = r;
    // Bitwise on integers, not on bools: no branch, and no warning from clang.
    straddling += static_cast<std::size_t>(static_cast<unsigned>(r.first[0] != r.last[0]) |
                                           static_cast<unsigned>(r.first[1] != r.last[1]) |
                                           static_cast<unsigned>(r.first[2] != r.last[2]));
  }
  straddling_ = straddling;
  // The straddlers' other cells, within the cap on entries.
  const std::uint64_t cap = kMaxEntriesPerBox * boxes.size();
  std::uint64_t entries = boxes.size();
  for (const Range& r : std::span<const Range>(straddlerRanges_).first(straddling_)) {
    entries += std::uint64_t{r.last[0] - r.first[0] + 1u} * (r.last[1] - r.first[1] + 1u) *
                   (r.last[2] - r.first[2] + 1u) - 1;
    if (entries > cap) return false;
    forEachOtherCell(r, [&](std::uint64_t cell) { ++offsets_[cell]; });
  }
  return true;
}

template <typename F>
void UniformGrid::forEachOtherCell(const Range& r, F&& f) const {
  const std::uint64_t nx = axes_[0].cells(), ny = axes_[1].cells();
  for (std::uint32_t z = r.first[2]; z <= r.last[2]; ++z)
    for (std::uint32_t y = r.first[1]; y <= r.last[1]; ++y)
      for (std::uint32_t x = r.first[0]; x <= r.last[0]; ++x)
        if (x != r.first[0] || y != r.first[1] || z != r.first[2]) f((z * ny + y) * nx + x);
}

void UniformGrid::build(std::span<const KeyBox> boxes, std::size_t cellSize, const CellSink& onCell) {
  checkObjectCount(boxes.size());
  if (cellSize < 1) cellSize = 1;
  cells_.clear();
  chooseResolution(boxes, cellSize);
  const std::uint32_t nx = axes_[0].cells(), ny = axes_[1].cells(), nz = axes_[2].cells();
  const std::size_t cellCount = std::size_t{nx} * ny * nz;
  offsets_.assign(cellCount, 0);
  fellBack_ = !countBoxes(boxes);
  if (fellBack_) {
    fallback_.build(boxes, cellSize, onCell);
    return;
  }
  // Prefix sum: each cell's count becomes its first item.
  std::uint64_t total = 0;
  cells_.reserve(cellCount);
  for (std::uint32_t z = 0; z < nz; ++z)
    for (std::uint32_t y = 0; y < ny; ++y)
      for (std::uint32_t x = 0; x < nx; ++x) {
        std::uint64_t& at = offsets_[(std::uint64_t{z} * ny + y) * nx + x];
        const std::uint64_t count = at;
        at = total;
        cells_.push_back({total,
                          static_cast<std::uint32_t>(count),
                          {axes_[0].planes[x], axes_[1].planes[y], axes_[2].planes[z]},
                          {axes_[0].planes[x + 1], axes_[1].planes[y + 1], axes_[2].planes[z + 1]}});
        total += count;
      }
  items_.resize(total);
  // Scatter (offsets_ becomes the cursor): every box into its first cell,
  // then the straddlers into their others.
  for (std::size_t i = 0; i < boxes.size(); ++i) items_[offsets_[firstCell_[i]]++] = static_cast<std::uint32_t>(i);
  for (std::size_t k = 0; k < straddling_; ++k) {
    const std::uint32_t id = straddlers_[k];
    forEachOtherCell(straddlerRanges_[k], [&](std::uint64_t cell) { items_[offsets_[cell]++] = id; });
  }
  if (!onCell) return;
  for (const Cell& cell : cells_) onCell(cell, {items_.data() + cell.begin, cell.count}, {});
}

}  // namespace bpaccel
