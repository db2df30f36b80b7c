#include "step_timing.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "core/median.hpp"

namespace bpaccel {

double StepTimes::median() const {
  if (stepSeconds.empty()) throw std::logic_error("StepTimes::median: no frame was timed");
  return bpaccel::median(stepSeconds);
}

StepTimes timeWholeSteps(const SceneConfig& scene, const BtBroadphaseFactory& makeBroadphase, std::size_t frames,
                         std::size_t warmup) {
  BouncingCubeScene world(scene, makeBroadphase());
  for (std::size_t f = 0; f < warmup; ++f) world.step();
  StepTimes times;
  times.stepSeconds.reserve(frames);
  for (std::size_t f = 0; f < frames; ++f) {
    const auto start = std::chrono::steady_clock::now();
    world.step();
    times.stepSeconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return times;
}

}  // namespace bpaccel
