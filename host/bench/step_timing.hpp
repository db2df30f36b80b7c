#pragma once
// Whole-step timing: how long a full stepSimulation of the bouncing-cube
// world takes with a given broad phase (broad phase, narrow phase, solver).

#include <functional>
#include <memory>
#include <vector>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>

#include "scene.hpp"

namespace bpaccel {

using BtBroadphaseFactory = std::function<std::unique_ptr<btBroadphaseInterface>()>;

struct StepTimes {
  std::vector<double> stepSeconds;  // one per timed frame, in order (steady clock)
  double median() const;
};

/// Builds the world from `scene` with the factory's broad phase, steps it
/// `warmup` frames untimed, then times `frames` calls of stepSimulation.
StepTimes timeWholeSteps(const SceneConfig& scene, const BtBroadphaseFactory& makeBroadphase, std::size_t frames,
                         std::size_t warmup);

}  // namespace bpaccel
