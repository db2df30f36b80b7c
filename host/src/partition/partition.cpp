#include "partition.hpp"

#include <stdexcept>

#include "kd_tree.hpp"
#include "uniform_grid.hpp"

namespace bpaccel {

std::unique_ptr<Partition> makePartition(PartitionKind kind) {
  if (kind == PartitionKind::UniformGrid) return std::make_unique<UniformGrid>();
  return std::make_unique<KdTree>();
}

std::string_view partitionName(PartitionKind kind) {
  switch (kind) {
    case PartitionKind::UniformGrid: return "grid";
    case PartitionKind::Automatic: return "auto";
    case PartitionKind::KdTree: break;
  }
  return "k-d";
}

PartitionKind parsePartitionKind(const std::string& text) {
  if (text == "kd") return PartitionKind::KdTree;
  if (text == "grid") return PartitionKind::UniformGrid;
  if (text == "auto") return PartitionKind::Automatic;
  throw std::invalid_argument("partition '" + text + "' is not 'kd', 'grid' or 'auto'");
}

}  // namespace bpaccel
