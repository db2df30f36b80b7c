#pragma once
// The broad phase's own choice of partition and cell size, frame by frame,
// from cheap statistics of the frame and of the last one's cells.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "../core/types.hpp"
#include "partition.hpp"

namespace bpaccel {

/// A partition kind and a cell size (none: the scene is one cell).
struct CellChoice {
  PartitionKind kind = PartitionKind::UniformGrid;
  std::optional<std::size_t> cellSize;
  friend bool operator==(const CellChoice&, const CellChoice&) = default;
};
/// "grid 64", "k-d 256", "one cell".
std::string choiceName(const CellChoice& choice);

/// What a frame's cells were like: the occupancy the next frame's choice
/// reads (the entries are the boxes' places in cells, a box in each cell it touches).
struct CellOccupancy {
  std::size_t objects = 0;
  std::uint64_t entries = 0;      // sum of the cells' box counts
  std::uint64_t squares = 0;      // sum of the squares of the cells' box counts
  std::uint64_t cells = 0;        // cells with at least one box
  bool fellBack = false;          // the grid handed the frame to the k-d tree
  /// The box-weighted mean cell: the count of the cell an entry picked at random lies in.
  double meanCell() const { return entries ? static_cast<double>(squares) / static_cast<double>(entries) : 0; }
  /// Entries per box: how many cells a box touches, on average.
  double entriesPerBox() const { return objects ? static_cast<double>(entries) / static_cast<double>(objects) : 0; }
};

/// The occupancy of a partition's last build.
CellOccupancy occupancyOf(const Partition& partition, std::size_t objects);

/// The rule (docs/host.md, "The automatic choice"). Keeps what it learnt of
/// the scene from one frame to the next; one per broad phase.
class AutomaticChoice {
 public:
  /// Scenes up to this many boxes are one cell.
  static constexpr std::size_t kOneCellUpTo = 96;
  /// The grid's cell size at the first frame of a scene.
  static constexpr std::size_t kFirstCellSize = 64;

  /// This frame's choice for `objects` boxes within `bounds`; `kind`
  /// Automatic lets the rule choose the kind too, else only the cell size.
  CellChoice choose(std::size_t objects, const KeyBounds& bounds, PartitionKind kind);
  /// The cells the choice gave (from occupancyOf); the next choice reads them.
  void observe(const CellChoice& used, const CellOccupancy& occupancy);

 private:
  std::optional<CellChoice> last_;
  CellOccupancy lastOccupancy_;
};

}  // namespace bpaccel
