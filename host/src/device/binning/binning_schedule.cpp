#include "binning_schedule.hpp"

#include <algorithm>

namespace bpaccel::binning {
namespace {

unsigned cellOf(std::uint32_t key, unsigned shift) { return key >> shift; }

/// The first error box i raises, if any (None: it is fine).
FrameError boxError(const BinningParams& p, const FrameCommand& f, std::size_t i) {
  if (i >= f.count()) return FrameError::LengthMismatch;
  const KeyBox& b = f.boxes[i];
  const std::uint64_t limit = std::uint64_t{1} << p.keyWidth;
  for (int a = 0; a < 3; ++a)
    if (b.min[a] >= limit || b.max[a] >= limit) return FrameError::KeyTooWide;
  for (int a = 0; a < 3; ++a)
    if (b.min[a] > b.max[a]) return FrameError::BoxInverted;
  for (int a = 0; a < 3; ++a)
    if (cellOf(b.max[a], f.shift) >= f.dims[a]) return FrameError::KeyOutOfGrid;
  for (int a = 0; a < 3; ++a)
    if (cellOf(b.max[a], f.shift) - cellOf(b.min[a], f.shift) > 1) return FrameError::BoxSpansCells;
  return FrameError::None;
}

FrameError headerError(const BinningParams& p, const FrameCommand& f) {
  if (f.count() > p.boxCapacity) return FrameError::CountOverCapacity;
  if (f.shift > p.maxShift()) return FrameError::BadGrid;
  for (unsigned d : f.dims)
    if (d < 1 || d > p.maxDim()) return FrameError::BadGrid;
  return FrameError::None;
}

/// Box i's entries, x fastest within y within z.
void entriesOf(const FrameCommand& f, std::uint32_t i, std::vector<Entry>& out) {
  const KeyBox& b = f.boxes[i];
  std::array<unsigned, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) lo[a] = cellOf(b.min[a], f.shift), hi[a] = cellOf(b.max[a], f.shift);
  out.clear();
  for (unsigned z = lo[2]; z <= hi[2]; ++z)
    for (unsigned y = lo[1]; y <= hi[1]; ++y)
      for (unsigned x = lo[0]; x <= hi[0]; ++x) {
        const auto starts = static_cast<std::uint8_t>((x == lo[0]) | (y == lo[1]) << 1 | (z == lo[2]) << 2);
        out.push_back({i, {x, y, z}, starts});
      }
}

}  // namespace

Binned bin(const BinningParams& p, const FrameCommand& f) {
  Binned r;
  r.groups.resize(p.groups());
  if ((r.error = headerError(p, f)) != FrameError::None) return r;
  std::vector<Entry> entries;
  for (std::size_t i = 0; i < f.boxes.size(); ++i) {
    if ((r.error = boxError(p, f, i)) != FrameError::None) {
      r.detail = i;
      return r;
    }
    entriesOf(f, static_cast<std::uint32_t>(i), entries);
    // Neighbouring cells lie in different groups: each entry goes to a group of its own.
    const bool full = std::any_of(entries.begin(), entries.end(), [&](const Entry& e) {
      return r.groups[p.groupOf(e.cell)].size() + 1 > p.groupCapacity;
    });
    if (full) {
      r.error = FrameError::GroupOverflow;
      r.detail = i;
      return r;
    }
    for (const Entry& e : entries) r.groups[p.groupOf(e.cell)].push_back(e);
  }
  if (f.boxes.size() < f.count()) {
    r.error = FrameError::LengthMismatch;
    r.detail = f.boxes.size();
  }
  return r;
}

namespace {

/// The issues of one cell (entries in memory order) on g lanes, appended to `s`.
void scheduleCell(const BinningParams& p, const FrameCommand& f, const std::vector<const Entry*>& cell,
                  const ScheduleFaults& faults, GroupSchedule& s) {
  const std::size_t n = cell.size(), g = p.lanesPerGroup;
  s.ops.push_back({true, 0, 0});
  for (std::size_t base = 0; base + 2 <= n; base += g)
    for (std::size_t d = 0; base + 1 + d < n; ++d) {
      Op op{false, static_cast<std::uint32_t>(s.hits.size()), 0};
      for (std::size_t k = 0; k < g && base + 1 + d + k < n; ++k) {
        const Entry& a = *cell[base + k];
        const Entry& b = *cell[base + 1 + d + k];
        const bool once = faults.skipExactlyOnce || ((a.starts | b.starts) & 7) == 7;
        if (once && overlaps(f.boxes[a.box], f.boxes[b.box])) s.hits.emplace_back(a.box, b.box);
      }
      op.hitEnd = static_cast<std::uint32_t>(s.hits.size());
      s.ops.push_back(op);
    }
}

}  // namespace

GroupSchedule scheduleGroup(const BinningParams& p, const FrameCommand& f, const std::vector<Entry>& entries,
                            const ScheduleFaults& faults) {
  const auto local = p.localDims(f.dims);
  std::vector<std::vector<const Entry*>> cells(std::size_t{local[0]} * local[1] * local[2]);
  for (const Entry& e : entries) {
    const std::size_t lx = e.cell[0] >> p.groupBits[0], ly = e.cell[1] >> p.groupBits[1],
                      lz = e.cell[2] >> p.groupBits[2];
    cells[lx + local[0] * (ly + local[1] * lz)].push_back(&e);
  }
  GroupSchedule s;
  s.cellSizes.reserve(cells.size());
  for (const auto& cell : cells) {
    s.cellSizes.push_back(static_cast<std::uint32_t>(cell.size()));
    if (cell.size() >= 2) scheduleCell(p, f, cell, faults, s);
  }
  return s;
}

}  // namespace bpaccel::binning
