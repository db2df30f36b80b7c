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

/// The grid's build state, outside the class so that it reads as data.
namespace grid_build {

struct Range {
  std::array<std::uint16_t, 3> first, last;  // cells per axis (at most UniformGrid::kMaxCellsPerAxis)
};
// A straddler's entry in one of its other cells.
struct Extra {
  std::uint64_t cell;
  std::uint32_t id;
  std::uint8_t below;  // the box's below() bits in that cell
};
// One thread's share of a build: the boxes [begin, end), and per cell how
// many of them have it as first cell and how many other entries its
// straddlers put there (then the cursors of the scatter).
struct Part {
  std::size_t begin = 0, end = 0;
  std::vector<std::uint64_t> firstCounts, extraCounts;
  std::vector<std::uint32_t> straddlers;  // boxes in more than one cell (place in the part), with their ranges
  std::vector<Range> ranges;
  std::size_t straddling = 0;             // how many of those two hold this frame's straddlers
  std::vector<Extra> extras;              // the straddlers' entries in their other cells
  std::size_t extraCount = 0;             // how many of those this frame holds
  std::uint64_t entries = 0;              // the part's boxes and their extra entries
};

}  // namespace grid_build

/// A counting sort of the boxes into the cells of a grid: one pass finds each
/// box's range of cells and counts the cells' boxes, a prefix sum places the
/// cells, a second pass scatters the boxes' indices. A box that straddles
/// grid planes joins every cell it touches; cells are half-open regions
/// [lo, hi) that cover key space (the outer planes are 0 and 2^32), so the
/// reference-point rule of BroadPhase holds exactly as on the tree.
///
/// Then the boxes themselves (the device's layout) are gathered in cell
/// order into one array that lives until the next build, and a batch refers
/// to the cells' spans of it instead of copying every box into the batch
/// (cellsOutliveBuild). Gathering in cell order was measured cheaper than
/// scattering the boxes beside their indices (bpaccel pairs --repeat, 8000
/// boxes): the writes fill one cache line at a time.
///
/// In steps (buildInSteps), the grid gathers the boxes slab by slab (the
/// cells of one z index) once every item is placed, and says after each
/// slab that its cells are final: a device starts on the first slab's cells
/// while the host gathers the others, at no cost in work. (Scattering by
/// slabs too was measured: its sort of the entries by slab cost the bench's
/// frame about 20 µs of host work, more than it moved the first cells forward.)
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
/// A box's cell on an axis is computed, not looked up: cell(key) =
/// clamp(trunc((value(key) / 2 - from / 2) * scale), 0, cells - 1) in float
/// arithmetic, eight keys at a time with AVX2 or four with SSE2 (value: the key's float,
/// clamped to the finite ones; the halves keep the difference finite). Each
/// step is monotone in the key (IEEE rounding is), so cell(key) never
/// decreases and a cell's region is exactly the keys that map to it; its
/// planes are found by a binary search over the keys with the same function.
/// A box joins the cells from its min's to its max's, and any point inside it
/// maps between them: exactness rests on monotonicity only, the float values
/// only make the cells about even in world units.
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

  void build(std::span<const KeyBox> boxes, std::size_t cellSize, const CellSink& onCell,
             const KeyBounds* bounds = nullptr) override;
  std::string_view name() const override { return "grid"; }
  bool needsBounds() const override { return true; }
  void buildInSteps(std::span<const KeyBox> boxes, std::size_t cellSize, const StepSink& onStep,
                    const KeyBounds* bounds = nullptr) override;
  /// The cells and their items and bits, counted and placed on the pool's
  /// threads (each a contiguous part of the boxes, the same cells and items
  /// in the same order as on one), without packing the boxes.
  void buildIndex(std::span<const KeyBox> boxes, std::size_t cellSize, const KeyBounds* bounds,
                  ThreadPool* pool) override;
  const std::vector<Cell>& cells() const override { return fellBack_ ? fallback_.cells() : cells_; }
  std::span<const std::uint32_t> items(const Cell& cell) const override {
    if (fellBack_) return fallback_.items(cell);
    return {items_.data() + cell.begin, cell.count};
  }
  /// The cells' boxes in the device's layout, like items(cell) (empty after a fallback or buildIndex).
  std::span<const KeyBox> packed(const Cell& cell) const override {
    if (fellBack_ || !gathered_) return {};
    return {packed_.data() + cell.begin, cell.count};
  }
  /// Known without comparing keys: a box's first cell (its min's) lies at or
  /// above the cell on every axis; a straddler's other cells are the offsets
  /// from its first, and an offset on an axis is that axis's bit (see
  /// forEachOtherCell). Empty after a fallback.
  std::span<const std::uint8_t> below(const Cell& cell) const override {
    if (fellBack_) return {};
    return {itemBelow_.data() + cell.begin, cell.count};
  }
  bool cellsOutliveBuild() const override { return !fellBack_; }

  /// Whether the last build gave the scene to the k-d tree (see above).
  bool fellBack() const { return fellBack_; }
  /// Cells per axis of the last build (without a fallback).
  std::array<std::uint32_t, 3> resolution() const;
  /// Item entries the grid's buffers hold (their capacity).
  std::size_t storedItems() const {
    std::size_t n = items_.capacity() + itemBelow_.capacity() + firstCell_.capacity();
    for (const Part& p : parts_)
      n += p.firstCounts.capacity() + p.extraCounts.capacity() + p.straddlers.capacity() + p.ranges.capacity() +
           p.extras.capacity();
    return n;
  }
  /// Boxes the grid's packed copy holds (its capacity).
  std::size_t storedBoxes() const { return packed_.capacity(); }

 private:
  // One axis: the cell function's constants and its planes (planes[c] is
  // the first key of cell c; planes[0] = 0, planes[cells] = 2^32).
  struct Axis {
    std::vector<std::uint64_t> planes;
    float fromHalf = 0, scale = 0, last = 0;  // half the lowest value, cells per half unit, cells - 1
    std::uint32_t keyLo = 0, keyHi = 0;       // the scene's bounds on the axis
    std::uint32_t cells() const { return static_cast<std::uint32_t>(planes.size() - 1); }
    std::uint32_t cellOf(std::uint32_t key) const;
    void place(std::uint32_t keyLo, std::uint32_t keyHi, std::uint32_t cells);
  };
  using Range = grid_build::Range;
  using Extra = grid_build::Extra;
  using Part = grid_build::Part;
  void countFirstCells(std::span<const KeyBox> boxes, Part& part);  // first cells; the straddlers listed
  bool countOtherCells(Part& part, std::uint64_t cap);               // the straddlers' other cells, within the cap
  // Resolution, counts, cells and every item placed with its bits; false
  // when the grid falls back to the tree (fellBack_), which is then not built.
  bool place(std::span<const KeyBox> boxes, std::size_t cellSize, const KeyBounds* bounds, ThreadPool* pool);
  std::uint64_t placeCells();  // the cells from the parts' counts; returns the items' total
  void scatter(Part& part);
  // The boxes of cells [from, to) gathered in cell order (packed_).
  void gather(std::span<const KeyBox> boxes, std::size_t from, std::size_t to);
  void chooseResolution(std::span<const KeyBox> boxes, std::size_t cellSize, const KeyBounds& bounds);

  std::array<Axis, 3> axes_;
  std::vector<std::uint32_t> firstCell_;  // each box's first cell (its min corner's)
  std::vector<Part> parts_;
  std::vector<std::uint32_t> items_;     // the cells' item lists, in cell order
  std::vector<std::uint8_t> itemBelow_;  // each item's below() bits, in the same order
  std::vector<KeyBox> packed_;           // their boxes, in the same order
  std::vector<Cell> cells_;
  KdTree fallback_;
  bool fellBack_ = false;
  bool gathered_ = false;                // packed_ holds this build's boxes
};

}  // namespace bpaccel
