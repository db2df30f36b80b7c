#pragma once
// FCL 0.7's broad-phase collision managers as benchmark methods.

#include <memory>
#include <vector>

#include "methods/timed_method.hpp"

namespace bpaccel {

/// One FCL manager over one collision object per box, kept across frames as
/// FCL users keep it: each frame sets every object's AABB, calls the
/// manager's update() and collide() with a callback that only records the pair.
class FclManager final : public TimedMethod {
 public:
  enum class Kind { DynamicAabbTree, SweepAndPrune, SpatialHashing };
  FclManager(Kind kind, const SceneStart& start);
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

/// FCL's three broad-phase managers. The SaP manager, rebuilt every frame, is
/// skipped where more than `maxSweepTests` pairs overlap on x (sweepSkipReason).
std::vector<MethodSpec> fclMethods(double maxSweepTests);

}  // namespace bpaccel
