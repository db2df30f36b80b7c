#pragma once
// A uniform grid over the scene's bounds: the k-d tree's cells for a fraction
// of its work on near-uniform scenes.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "kd_tree.hpp"
#include "partition.hpp"

namespace bpaccel {

/// A counting sort of the boxes into the cells of a grid: one pass finds each
/// box's range of cells and counts the cells' boxes, a prefix sum places the
/// cells, a second pass scatters the boxes' indices. A box that straddles
/// grid planes joins every cell it touches; cells are half-open regions
/// [lo, hi) that cover key space (the outer planes are 0 and 2^32), so the
/// reference-point rule of BroadPhase holds exactly as on the tree.
///
/// Cells are handed over with indices only (BroadPhase gathers their boxes):
/// scattering the boxes too was measured slower per frame (bpaccel pairs
/// --repeat, 8000 boxes): with the device simulated between frames their 24
/// bytes a box land in cold cache lines, and a batch copies them again anyway.
///
/// Resolution: the planes are evenly spaced in float space (world units)
/// between the scene's lowest box minimum and highest box maximum, since keys
/// are float bits and even steps in key space are logarithmic in world space
/// (a scene around 0 would put nearly every box into one key-space cell).
/// The grid aims at ceil(2n / cellSize) cells, cubic in world units as far as
/// the bounds allow (per-axis counts in proportion to the scene's extents, an
/// axis without extent gets one): on average cellSize/2 boxes a cell before
/// straddlers join, about what the tree's leaves hold (between cellSize/2
/// and cellSize) once they have.
///
/// A box's cell on an axis is looked up in a table over the scene's key
/// range, one entry per bucket of 2^shift keys: cell = table[(key - keyLo)
/// >> shift]. The table never decreases, so a cell's region is exactly the
/// keys of its buckets, and each plane is the first key of a bucket: a box
/// joins the cells from its min's to its max's, and any point inside it maps
/// between them, with no float arithmetic on the way. Float arithmetic only
/// places the planes: evenly in world units, each rounded up to a bucket
/// boundary. Buckets are evenly spaced in key space, i.e. coarsest at the
/// scene's largest magnitude; the shift makes a bucket there at most an
/// eighth of a cell (at most kMaxBuckets buckets: beyond, cells snap to
/// coarser steps, still exactly).
///
/// Bounds on memory: at most kMaxCellsPerAxis cells per axis and about
/// ceil(2n / cellSize) cells in all (each axis's count rounded). Boxes large
/// against the cells would join many cells: once the cells joined exceed
/// kMaxEntriesPerBox per box, the build stops and falls back to the k-d tree
/// for this frame, which never copies more than a quarter of a node's boxes
/// into both children. The work before the fallback is bounded by the same
/// cap.
class UniformGrid final : public Partition {
 public:
  static constexpr std::uint64_t kMaxEntriesPerBox = 4;
  static constexpr std::uint32_t kMaxCellsPerAxis = 1024;

  void build(std::span<const KeyBox> boxes, std::size_t cellSize, const CellSink& onCell) override;
  std::string_view name() const override { return "grid"; }
  const std::vector<Cell>& cells() const override { return fellBack_ ? fallback_.cells() : cells_; }
  std::span<const std::uint32_t> items(const Cell& cell) const override {
    if (fellBack_) return fallback_.items(cell);
    return {items_.data() + cell.begin, cell.count};
  }

  /// Whether the last build gave the scene to the k-d tree (see above).
  bool fellBack() const { return fellBack_; }
  /// Cells per axis of the last build (without a fallback).
  std::array<std::uint32_t, 3> resolution() const;
  /// Item entries the grid's buffers hold (their capacity).
  std::size_t storedItems() const {
    return items_.capacity() + offsets_.capacity() + firstCell_.capacity() +
           straddlers_.capacity() + straddlerRanges_.capacity();
  }

 private:
  // One axis: the bucket table and the planes (planes[c] is the first key of
  // cell c; planes[0] = 0, planes[cells] = 2^32).
  struct Axis {
    std::vector<std::uint64_t> planes;
    std::vector<std::uint16_t> table;  // cell of each bucket, never decreasing
    std::uint32_t keyLo = 0;
    unsigned shift = 0;
    std::uint32_t cells() const { return static_cast<std::uint32_t>(planes.size() - 1); }
    // The cell of a key in [keyLo, keyHi] (every box's keys are).
    struct Lookup {
      const std::uint16_t* table;
      std::uint64_t keyLo;
      unsigned shift;
      std::uint16_t cellOf(std::uint32_t key) const { return table[(key - keyLo) >> shift]; }
    };
    Lookup lookup() const { return {table.data(), keyLo, shift}; }
    void place(std::uint32_t keyLo, std::uint32_t keyHi, std::uint32_t cells);
  };
  static constexpr std::uint64_t kMaxBuckets = 8192;
  struct Range {
    std::array<std::uint16_t, 3> first, last;  // cells per axis (at most kMaxCellsPerAxis)
  };
  // Counts each cell's boxes into offsets_; false when the boxes would join too many cells.
  bool countBoxes(std::span<const KeyBox> boxes);
  void chooseResolution(std::span<const KeyBox> boxes, std::size_t cellSize);
  // Calls f(cell) for each cell of r but its first.
  template <typename F>
  void forEachOtherCell(const Range& r, F&& f) const;

  std::array<Axis, 3> axes_;
  std::vector<std::uint32_t> firstCell_;  // each box's first cell (its min corner's)
  std::vector<std::uint32_t> straddlers_;  // boxes in more than one cell, with their ranges
  std::vector<Range> straddlerRanges_;
  std::size_t straddling_ = 0;            // how many of those two hold this frame's straddlers
  std::vector<std::uint64_t> offsets_;   // per cell: its count, then its first item, then the scatter cursor
  std::vector<std::uint32_t> items_;     // the cells' item lists, in cell order
  std::vector<Cell> cells_;
  KdTree fallback_;
  bool fellBack_ = false;
};

}  // namespace bpaccel
