#pragma once
// A partition of key space into cells, each with the boxes that touch it: what
// BroadPhase hands to the backend cell by cell. Two kinds: the k-d tree
// (kd_tree.hpp, any scene) and the uniform grid (uniform_grid.hpp, cheaper on
// near-uniform scenes).

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "../core/types.hpp"

namespace bpaccel {

class ThreadPool;

/// One cell: a half-open region [lo, hi) of key space and its boxes. The
/// cells of a partition cover key space without overlap, and every box is in
/// every cell whose region it touches, so every point p lies in exactly one
/// cell and that cell holds every box that contains p.
struct Cell {
  std::uint64_t begin;               // offset of the first item in Partition::items()
  std::uint32_t count;               // number of boxes in the cell
  std::array<std::uint64_t, 3> lo;   // region, inclusive
  std::array<std::uint64_t, 3> hi;   // region, exclusive (up to 2^32)
  bool contains(const std::array<std::uint32_t, 3>& p) const {
    return lo[0] <= p[0] && p[0] < hi[0] && lo[1] <= p[1] && p[1] < hi[1] && lo[2] <= p[2] && p[2] < hi[2];
  }
};

/// Called with each cell as soon as it is final, with its items and, when the
/// partition has them, their boxes in the same order (packed; else empty).
/// All three are valid during the call only.
using CellSink = std::function<void(const Cell&, std::span<const std::uint32_t> items, std::span<const KeyBox> packed)>;

/// Called with k each time cells()[0, k) are final (buildInSteps).
using StepSink = std::function<void(std::size_t finalCells)>;

/// Built anew every frame from the frame's boxes; storage is kept between builds.
class Partition {
 public:
  virtual ~Partition() = default;
  /// "k-d" or "grid": the method rows' and the CLI's name.
  virtual std::string_view name() const = 0;
  /// Partitions `boxes` into cells of about `cellSize` boxes (what "about"
  /// means is each kind's own rule) and hands each cell to `onCell` (if any).
  /// A cell may hold more than cellSize boxes; BroadPhase chunks cells
  /// above the backend's capacity. `bounds`: the boxes' bounds when the
  /// caller has them already (toKeys finds them while converting), else a
  /// kind that needs them finds them itself.
  virtual void build(std::span<const KeyBox> boxes, std::size_t cellSize, const CellSink& onCell,
                     const KeyBounds* bounds = nullptr) = 0;
  /// Whether build uses the boxes' bounds (then a caller that has them hands them over).
  virtual bool needsBounds() const { return false; }
  /// The last build's cells, in the order they were handed over.
  virtual const std::vector<Cell>& cells() const = 0;
  /// Box indices of a cell of the last build.
  virtual std::span<const std::uint32_t> items(const Cell& cell) const = 0;
  /// Whether the items and packed boxes the last build handed to its sink
  /// stay valid until the next build (a batch may then refer to them instead
  /// of copying); otherwise they are valid during the call only.
  virtual bool cellsOutliveBuild() const { return false; }
  /// Whether build hands each cell to its sink while it goes on (the tree:
  /// the first cell is ready long before the last). Otherwise a caller
  /// builds in steps (buildInSteps) and goes through cells() itself.
  virtual bool streamsCells() const { return false; }
  /// Builds as build() without a sink does, telling `onStep` each time a
  /// prefix of cells() is final: their items(), packed() and below() stay
  /// valid until the next build. For a partition that does not stream its
  /// cells: the caller goes through them itself, with no call through a
  /// sink and no clock read per cell. By default one step at the end.
  virtual void buildInSteps(std::span<const KeyBox> boxes, std::size_t cellSize, const StepSink& onStep,
                            const KeyBounds* bounds = nullptr) {
    build(boxes, cellSize, {}, bounds);
    if (onStep) onStep(cells().size());
  }
  /// Builds the cells and their items (and below() bits where the kind has
  /// them) for a caller that reads each cell's boxes itself from the keys:
  /// packed() may then be empty. A kind that can share the work does so on
  /// `pool` (if any); by default build() without a sink.
  virtual void buildIndex(std::span<const KeyBox> boxes, std::size_t cellSize, const KeyBounds* bounds,
                          ThreadPool* /*pool*/) {
    build(boxes, cellSize, {}, bounds);
  }
  /// A cell of the last build, its boxes packed in item order, when the
  /// partition keeps them until the next build; else empty.
  virtual std::span<const KeyBox> packed(const Cell&) const { return {}; }
  /// Per item of a cell of the last build, when the partition keeps them
  /// until the next build (else empty): bit a set when the box's min lies
  /// below the cell's region on axis a (belowBits). They decide a pair's
  /// reference point without its boxes (ownsPair).
  virtual std::span<const std::uint8_t> below(const Cell&) const { return {}; }
};

/// The bits of below(): axis a's bit set when `min[a] < lo[a]`.
inline std::uint8_t belowBits(const std::array<std::uint32_t, 3>& min, const std::array<std::uint64_t, 3>& lo) {
  return static_cast<std::uint8_t>(static_cast<unsigned>(min[0] < lo[0]) | static_cast<unsigned>(min[1] < lo[1]) << 1 |
                                   static_cast<unsigned>(min[2] < lo[2]) << 2);
}

/// Automatic: the broad phase chooses the kind (and, when the cell size is
/// automatic too, the cell size) frame by frame (automatic_choice.hpp).
enum class PartitionKind { KdTree, UniformGrid, Automatic };

/// The k-d tree or the grid (Automatic: the k-d tree, the kind a cell size
/// given alone has always meant).
std::unique_ptr<Partition> makePartition(PartitionKind kind);
/// "k-d", "grid" or "auto".
std::string_view partitionName(PartitionKind kind);
/// "kd", "grid" or "auto" (the CLI's spelling); throws std::invalid_argument naming the text otherwise.
PartitionKind parsePartitionKind(const std::string& text);

/// The reference point of an overlapping pair: the low corner of the two
/// boxes' intersection. It lies in both boxes, so exactly one cell holds it,
/// and that cell holds both boxes: a pair is reported only there.
inline std::array<std::uint32_t, 3> referencePoint(const KeyBox& a, const KeyBox& b) {
  return {std::max(a.min[0], b.min[0]), std::max(a.min[1], b.min[1]), std::max(a.min[2], b.min[2])};
}

/// The same rule from two boxes' below() bits in a cell that holds both: the
/// reference point's coordinate on an axis is the larger min, below the
/// region's hi since both boxes touch the region; it lies below the region's
/// lo exactly when both mins do.
inline bool ownsPair(std::uint8_t belowA, std::uint8_t belowB) { return (belowA & belowB) == 0; }

}  // namespace bpaccel
