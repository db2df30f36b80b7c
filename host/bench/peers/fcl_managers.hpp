#pragma once
// FCL 0.7's broad-phase collision managers as benchmark methods.

#include <memory>
#include <vector>

#include "methods/timed_method.hpp"

namespace bpaccel {

/// One FCL manager over one collision object per box, kept across frames as
/// FCL users keep it: each frame sets every object's AABB, tells the manager
/// (its Usage) and calls collide() with a callback that only records the pair.
class FclManager final : public TimedMethod {
 public:
  /// FCL's managers, and this project's (bpaccel::BroadPhaseManager on the cpu
  /// backend) behind the same FCL interface and callback.
  enum class Kind { DynamicAabbTree, SweepAndPrune, SpatialHashing, Bpaccel };
  /// How a frame's moves reach the manager, each a usage of FCL's API:
  /// - UpdateAll: update(), which for the tree refits the tree built for the
  ///   first frame and rebalances only when its height grows;
  /// - UpdateEach: update(objects), which for the tree re-inserts every
  ///   moved leaf where it now belongs (update(obj) per object does the same,
  ///   with a rebalancing pass after each);
  /// - Rebuild: clear(), registerObjects() and setup(), a fresh tree (or sweep) each frame.
  enum class Usage { UpdateAll, UpdateEach, Rebuild };
  /// `bpaccelCellSize`: the grid cell of Kind::Bpaccel's manager.
  FclManager(Kind kind, Usage usage, const SceneStart& start, std::size_t bpaccelCellSize = 64);
  ~FclManager() override;
  FclManager(const FclManager&) = delete;
  FclManager& operator=(const FclManager&) = delete;

  void update(std::span<const Aabb> boxes) override;
  void pairs(std::vector<Pair>& out) override { out = pairs_; }

 private:
  struct Impl;  // keeps FCL's and Eigen's headers out of the benchmark
  std::unique_ptr<Impl> impl_;
  std::vector<Pair> pairs_;
};

/// FCL's three broad-phase managers, the tree in each usage. The SaP manager,
/// rebuilt every frame, is skipped where more than `maxSweepTests` pairs
/// overlap on x (sweepSkipReason).
std::vector<MethodSpec> fclMethods(double maxSweepTests);
/// bpaccel::BroadPhaseManager (the cpu backend, grid partition of cell
/// `cellSize`) through FCL's interface, as the FCL rows run: an exact method.
MethodSpec bpaccelFclMethod(std::size_t cellSize = 64);

}  // namespace bpaccel
