#include "automatic_choice.hpp"

#include <fmt/format.h>

namespace bpaccel {

std::string choiceName(const CellChoice& choice) {
  if (!choice.cellSize) return "one cell";
  return fmt::format("{} {}", partitionName(choice.kind), *choice.cellSize);
}

CellOccupancy occupancyOf(const Partition& partition, std::size_t objects) {
  CellOccupancy o;
  o.objects = objects;
  for (const Cell& c : partition.cells()) {
    o.entries += c.count;
    o.squares += std::uint64_t{c.count} * c.count;
    o.cells += c.count > 0;
  }
  return o;
}

CellChoice AutomaticChoice::choose(std::size_t objects, const KeyBounds& /*bounds*/, PartitionKind kind) {
  if (kind == PartitionKind::Automatic && objects <= kOneCellUpTo) return {PartitionKind::UniformGrid, std::nullopt};
  const PartitionKind k = kind == PartitionKind::Automatic ? PartitionKind::UniformGrid : kind;
  std::size_t size = kFirstCellSize;
  // Only what this kind's cells told of the scene counts; a frame of one cell tells nothing.
  if (rule_ == SizeRule::MeanCellBand && last_ && last_->kind == k && last_->cellSize)
    size = nextCellSize(*last_->cellSize, lastOccupancy_);
  return {k, size};
}

std::size_t AutomaticChoice::nextCellSize(std::size_t size, const CellOccupancy& occupancy) {
  if (occupancy.entries == 0) return size;
  const double mean = occupancy.meanCell();
  if (mean > kMeanCellHigh && size / 2 >= kSmallestCellSize) return size / 2;
  if (mean < kMeanCellLow && size * 2 <= kLargestCellSize) return size * 2;
  return size;
}

void AutomaticChoice::observe(const CellChoice& used, const CellOccupancy& occupancy) {
  last_ = used;
  lastOccupancy_ = occupancy;
}

}  // namespace bpaccel
