#pragma once
// A batch of device cells, filled cell by cell and sealed for one hand-over.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "../partition/partition.hpp"
#include "device_cell.hpp"
#include "pair_filter.hpp"

namespace bpaccel {

/// A batch's cells: their items and boxes (referred to where they outlive the
/// batch, else copied back to back), and how to filter each cell's pairs. A
/// cell's region is copied: the tree's leaf list grows (and moves) while the
/// batch fills.
struct Batch {
  struct Pending {
    std::span<const std::uint32_t> items;  // when referred to
    std::span<const KeyBox> boxes;
    std::span<const std::uint8_t> below;   // the partition's below() bits, when referred to and it has them
    bool copied = false;
    std::size_t begin = 0, count = 0;  // when copied: where in the batch's items and boxes
    Cell region{};
    bool hasRegion = false;
    std::size_t splitAt = 0;
    int keep = 0;
    std::size_t deviceSplit = 0;
    std::size_t size() const { return copied ? count : boxes.size(); }
  };
  std::vector<Pending> cells;            // in the partition's order
  std::vector<std::uint32_t> order;      // the cells in the order the device gets them (made when sealed)
  std::vector<std::uint32_t> position;   // its inverse: where the device has cell k
  std::vector<std::uint32_t> items;      // copied cells' items
  std::vector<KeyBox> boxes;             // copied cells' boxes
  std::vector<std::span<const KeyBox>> cellSpans;  // in the device's order, full keys (made when sealed)
  std::vector<std::span<const std::uint32_t>> cellItems;
  std::vector<std::size_t> splits;       // the cells' device splits in the device's order; empty: none has one
  // With a narrow device: the cells' narrowed keys back to back, and the
  // spans the device gets instead of cellSpans (which decoding checks with).
  std::vector<KeyBox> narrowed;
  std::vector<std::span<const KeyBox>> narrowedSpans;

  /// How to filter the pairs of cell k (partition order) once sealed.
  PairFilter filter(std::size_t k) const;
  void clear() {
    cells.clear();
    items.clear();
    boxes.clear();
  }
};

/// Fills batches, with slow start: a frame's first batch is full at
/// `firstBatchCells` cells, each next one at twice as many, up to `cellsPerBatch`.
class BatchBuilder {
 public:
  BatchBuilder(std::size_t cellsPerBatch, std::size_t firstBatchCells, unsigned deviceKeyWidth);
  void startFrame();
  /// Adds a device cell, copying what does not last (gathering its boxes
  /// from `keys` where it has none packed); true when the batch is full.
  bool add(const DeviceCell& cell, std::span<const KeyBox> keys);
  bool empty() const { return batch_.cells.empty(); }
  /// Seals the batch for its hand-over: the cells in ascending size, their
  /// spans and splits, narrowed keys where the device compares fewer bits.
  /// Returns the cells as the device gets them. The next batch may be larger.
  std::span<const std::span<const KeyBox>> seal();
  /// The batch being filled, or just sealed (a hand-over may swap its storage).
  Batch& batch() { return batch_; }

 private:
  static constexpr std::size_t kSizeBuckets = 256;
  void sortBySize();
  std::span<const std::span<const KeyBox>> deviceCells();

  std::size_t cellsPerBatch_;
  std::size_t firstBatchCells_;
  unsigned keyWidth_;
  std::size_t limit_;  // cells that make the batch being filled full: doubles per hand-over
  Batch batch_;
  std::vector<std::uint32_t> bucketStarts_;  // the counting sort's
};

}  // namespace bpaccel
