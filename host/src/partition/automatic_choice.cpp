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
  return {k, kFirstCellSize};
}

void AutomaticChoice::observe(const CellChoice& used, const CellOccupancy& occupancy) {
  last_ = used;
  lastOccupancy_ = occupancy;
}

}  // namespace bpaccel
