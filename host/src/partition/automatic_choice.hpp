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
  /// The box-weighted mean cell: the count of the cell an entry picked at random lies in.
  double meanCell() const { return entries ? static_cast<double>(squares) / static_cast<double>(entries) : 0; }
  /// Entries per box: how many cells a box touches, on average.
  double entriesPerBox() const { return objects ? static_cast<double>(entries) / static_cast<double>(objects) : 0; }
};

/// The occupancy of a partition's last build.
CellOccupancy occupancyOf(const Partition& partition, std::size_t objects);

/// How the automatic cell size follows the scene.
enum class SizeRule {
  /// kFirstCellSize every frame: the device backends, whose lanes the cells fill.
  Fixed,
  /// From kFirstCellSize, halved or doubled each frame to keep the last
  /// frame's box-weighted mean cell within [kMeanCellLow, kMeanCellHigh]:
  /// the cpu backend, whose kernel is fastest on cells of tens of boxes.
  MeanCellBand,
};

/// The rule (docs/host.md, "The automatic choice"). Keeps what it learnt of
/// the scene from one frame to the next; one per broad phase.
class AutomaticChoice {
 public:
  /// Scenes up to this many boxes are one cell.
  static constexpr std::size_t kOneCellUpTo = 96;
  /// The cell size at the first frame of a scene (and every frame, SizeRule::Fixed).
  static constexpr std::size_t kFirstCellSize = 64;
  /// SizeRule::MeanCellBand's limits. Above kMeanCellHigh too many cells
  /// reach the kernel's sweep (AllPairsKernel::kSweepAbove boxes), which
  /// costs more a box than all pairs below it; under kMeanCellLow the
  /// entries (a box in each cell it touches) and the cells' fixed costs
  /// outweigh the tests saved. Doubling a cell size less than doubles the
  /// mean cell, so the band is over twice as wide as the step and a size
  /// never swings between two.
  static constexpr double kMeanCellLow = 28;
  static constexpr double kMeanCellHigh = 64;
  static constexpr std::size_t kSmallestCellSize = 16;
  static constexpr std::size_t kLargestCellSize = 512;

  explicit AutomaticChoice(SizeRule rule = SizeRule::Fixed) : rule_(rule) {}

  /// This frame's choice for `objects` boxes within `bounds`; `kind`
  /// Automatic lets the rule choose the kind too, else only the cell size.
  CellChoice choose(std::size_t objects, const KeyBounds& bounds, PartitionKind kind);
  /// The cells the choice gave (from occupancyOf); the next choice reads them.
  void observe(const CellChoice& used, const CellOccupancy& occupancy);

 private:
  // The next cell size after `size` gave cells of `occupancy`.
  static std::size_t nextCellSize(std::size_t size, const CellOccupancy& occupancy);

  SizeRule rule_;
  std::optional<CellChoice> last_;
  CellOccupancy lastOccupancy_;
};

}  // namespace bpaccel
