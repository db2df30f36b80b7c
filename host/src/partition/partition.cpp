#include "partition.hpp"

#include <stdexcept>

#include "kd_tree.hpp"
#include "uniform_grid.hpp"

namespace bpaccel {

std::unique_ptr<Partition> makePartition(PartitionKind kind) {
  if (kind == PartitionKind::UniformGrid) return std::make_unique<UniformGrid>();
  return std::make_unique<KdTree>();
}

std::string_view partitionName(PartitionKind kind) { return kind == PartitionKind::UniformGrid ? "grid" : "k-d"; }

PartitionKind parsePartitionKind(const std::string& text) {
  if (text == "kd") return PartitionKind::KdTree;
  if (text == "grid") return PartitionKind::UniformGrid;
  throw std::invalid_argument("partition '" + text + "' is neither 'kd' nor 'grid'");
}

}  // namespace bpaccel
