#pragma once
// Whole-step timing: how long a full stepSimulation of the bouncing-cube
// world takes with a given broad phase (broad phase, narrow phase, solver),
// and, as a game's frame does, broad-phase ray tests cast after each step.

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>

#include "scene.hpp"

namespace bpaccel {

using BtBroadphaseFactory = std::function<std::unique_ptr<btBroadphaseInterface>()>;

struct StepTimes {
  std::vector<double> stepSeconds;  // one per timed frame, in order (steady clock)
  std::vector<double> raySeconds;   // per timed frame: all its ray tests (empty without rays)
  /// Over every timed frame's rays, against Bullet's ray-box test on every
  /// proxy's box: proxies reported, and those wrongly added or missed.
  std::uint64_t rayHits = 0, rayExtra = 0, rayMissing = 0;
  double median() const;
};

struct WholeStepConfig {
  std::size_t frames = 20, warmup = 3;
  /// Broad-phase rayTests cast after each step (random segments inside the
  /// cube, the same for every broad phase of the same seed); 0: none.
  std::size_t rays = 0;
};

/// Builds the world from `scene` with the factory's broad phase, steps it
/// `warmup` frames untimed, then times `frames` calls of stepSimulation, each
/// followed by its timed and checked ray tests.
StepTimes timeWholeSteps(const SceneConfig& scene, const BtBroadphaseFactory& makeBroadphase,
                         const WholeStepConfig& config);

}  // namespace bpaccel
