#include "batch.hpp"

#include <algorithm>
#include <numeric>

#include "../core/keys.hpp"

namespace bpaccel {

PairFilter Batch::filter(std::size_t k) const {
  const Pending& cell = cells[k];
  const std::size_t c = position[k];
  return {cellItems[c], cellSpans[c], cell.below, cell.hasRegion ? &cell.region : nullptr, cell.splitAt, cell.keep};
}

BatchBuilder::BatchBuilder(std::size_t cellsPerBatch, std::size_t firstBatchCells, unsigned deviceKeyWidth)
    : cellsPerBatch_(cellsPerBatch), firstBatchCells_(firstBatchCells), keyWidth_(deviceKeyWidth),
      limit_(firstBatchCells) {}

void BatchBuilder::startFrame() {
  batch_.clear();
  limit_ = firstBatchCells_;
}

bool BatchBuilder::add(const DeviceCell& cell, std::span<const KeyBox> keys) {
  Batch::Pending p;
  if (cell.region) p.region = *cell.region;
  p.hasRegion = cell.region != nullptr;
  p.splitAt = cell.splitAt;
  p.keep = cell.keep;
  p.deviceSplit = cell.deviceSplit;
  if (cell.lasting && !cell.packed.empty()) {
    p.items = cell.items;
    p.boxes = cell.packed;
    p.below = cell.below;
  } else {
    p.copied = true;
    p.begin = batch_.items.size();
    p.count = cell.items.size();
    batch_.items.insert(batch_.items.end(), cell.items.begin(), cell.items.end());
    if (cell.packed.empty())
      for (const std::uint32_t id : cell.items) batch_.boxes.push_back(keys[id]);
    else
      batch_.boxes.insert(batch_.boxes.end(), cell.packed.begin(), cell.packed.end());
  }
  batch_.cells.push_back(p);
  return batch_.cells.size() >= limit_;
}

std::span<const std::span<const KeyBox>> BatchBuilder::seal() {
  limit_ = std::min(2 * limit_, cellsPerBatch_);
  sortBySize();
  Batch& b = batch_;
  b.cellSpans.clear();
  b.cellItems.clear();
  b.splits.clear();
  const bool anySplit = std::any_of(b.cells.begin(), b.cells.end(), [](const auto& c) { return c.deviceSplit != 0; });
  for (const std::uint32_t k : b.order) {
    const Batch::Pending& c = b.cells[k];
    if (anySplit) b.splits.push_back(c.deviceSplit);
    b.cellSpans.push_back(c.copied ? std::span<const KeyBox>(b.boxes).subspan(c.begin, c.count) : c.boxes);
    b.cellItems.push_back(c.copied ? std::span<const std::uint32_t>(b.items).subspan(c.begin, c.count) : c.items);
  }
  // Narrowed here, before the hand-over's clock starts: it is host work.
  return deviceCells();
}

// The cells go in ascending size. A device that loads the next cell while the
// current one runs (the stream's) hides those loads only under a run about as
// long; in the partition's order a small cell before a large one left the
// difference in the open (bench, 8000 boxes, grid 64: loads were about 1,030
// of 14,700 device cycles; in ascending size 320 of 14,000). Cells decode by
// their own records, so any order gives the same pairs. A counting sort:
// std::sort's mispredicted compares cost about a microsecond a batch of 64.
// Cells of kSizeBuckets - 1 boxes or more share the last bucket in the
// partition's order (the bench's cells rarely get there).
void BatchBuilder::sortBySize() {
  Batch& b = batch_;
  const auto bucketOf = [](const Batch::Pending& c) { return std::min(c.size(), kSizeBuckets - 1); };
  bucketStarts_.assign(kSizeBuckets + 1, 0);
  for (const Batch::Pending& c : b.cells) ++bucketStarts_[bucketOf(c) + 1];
  std::partial_sum(bucketStarts_.begin(), bucketStarts_.end(), bucketStarts_.begin());
  b.order.resize(b.cells.size());
  b.position.resize(b.cells.size());
  for (std::size_t k = 0; k < b.cells.size(); ++k) {
    const std::uint32_t at = bucketStarts_[bucketOf(b.cells[k])]++;
    b.order[at] = static_cast<std::uint32_t>(k);
    b.position[k] = at;
  }
}

std::span<const std::span<const KeyBox>> BatchBuilder::deviceCells() {
  Batch& b = batch_;
  if (keyWidth_ >= 32) return b.cellSpans;
  std::size_t total = 0;
  for (const auto& cell : b.cellSpans) total += cell.size();
  b.narrowed.resize(total);  // before any span into it is taken
  b.narrowedSpans.clear();
  std::size_t at = 0;
  for (const auto& cell : b.cellSpans) {
    const std::span<KeyBox> to(b.narrowed.data() + at, cell.size());
    narrowKeys(cell, keyWidth_, to);
    b.narrowedSpans.emplace_back(to);
    at += cell.size();
  }
  return b.narrowedSpans;
}

}  // namespace bpaccel
