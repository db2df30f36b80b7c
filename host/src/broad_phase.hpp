#pragma once
// A whole-scene broad phase: keys, optional k-d tree, chunking, backend runs.

#include <chrono>
#include <optional>
#include <span>
#include <vector>

#include "backend.hpp"
#include "kd_tree.hpp"
#include "types.hpp"

namespace bpaccel {

/// Host time of one findPairs call, by part (measured with a steady clock).
struct HostTimes {
  double convertSeconds = 0;  // float to key conversion and validation
  double treeSeconds = 0;     // k-d tree build
  double cellsSeconds = 0;    // packing, backend runs, decoding and filtering
  double backendSeconds = 0;  // inside Backend::run (simulating the device, or the cpu test itself)
  double totalSeconds = 0;    // all of the above (conversion only when the input was floats)
};

/// Finds every overlapping pair of a scene exactly once. Without a cell size
/// the scene is one cell. A cell larger than the backend's capacity is
/// covered in chunks of capacity/2 boxes: every two chunks run together, and
/// each pair is kept from exactly one of those runs.
class BroadPhase {
 public:
  BroadPhase(Backend& backend, std::optional<std::size_t> cellSize);

  /// Appends the pairs (i < j, unsorted) to `out` (cleared first).
  void findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);
  /// The same on boxes already converted to keys.
  void findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out);

  const RunStats& stats() const { return stats_; }
  const HostTimes& times() const { return times_; }
  const KdTree& tree() const { return tree_; }

 private:
  void processCell(std::span<const KeyBox> keys, std::span<const std::uint32_t> items, const KdTree::Leaf* region,
                   std::vector<Pair>& out);
  void runBatch(std::span<const KeyBox> keys, std::span<const std::uint32_t> items, const KdTree::Leaf* region,
                std::vector<Pair>& out, std::size_t splitAt, int keepMode);

  Backend& backend_;
  std::optional<std::size_t> cellSize_;
  KdTree tree_;
  std::vector<KeyBox> keys_;
  std::vector<KeyBox> batch_;           // a cell's boxes, packed for the backend
  std::vector<std::uint32_t> identity_; // 0..n-1: the scene as one cell
  std::vector<Pair> local_;             // pairs of one run, batch indices
  RunStats stats_;
  HostTimes times_;
};

}  // namespace bpaccel
