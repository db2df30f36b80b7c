#pragma once
// ODE 0.16's collision spaces as benchmark methods.

#include <memory>
#include <vector>

#include "methods/timed_method.hpp"

namespace bpaccel {

/// One ODE space holding one box geom per object, kept across frames as ODE
/// users keep it: each frame moves and resizes every geom to its box (ODE
/// recomputes the dirty AABBs inside the collide call) and calls
/// dSpaceCollide with a near callback that only records the pair.
class OdeSpace final : public TimedMethod {
 public:
  enum class Kind { Hash, SweepAndPrune };
  OdeSpace(Kind kind, const SceneStart& start);
  ~OdeSpace() override;
  OdeSpace(const OdeSpace&) = delete;
  OdeSpace& operator=(const OdeSpace&) = delete;

  void update(std::span<const Aabb> boxes) override;
  void pairs(std::vector<Pair>& out) override { out = pairs_; }

 private:
  struct Impl;  // keeps ODE's headers out of the benchmark
  std::unique_ptr<Impl> impl_;
  std::vector<Pair> pairs_;
};

/// Why dHashSpace cannot run at `objects`, if it cannot: its table of tested
/// pairs (n^2/8 bytes) overflows an int beyond 131,071 objects and ODE aborts.
std::optional<std::string> hashSpaceSkipReason(std::size_t objects);

/// ODE's hash space and sweep-and-prune space. The latter is skipped where
/// more than `maxSweepTests` pairs overlap on x (sweepSkipReason).
std::vector<MethodSpec> odeMethods(double maxSweepTests);

}  // namespace bpaccel
