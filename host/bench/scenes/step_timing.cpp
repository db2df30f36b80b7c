#include "step_timing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>

#include <btBulletDynamicsCommon.h>

#include "bullet/bullet_drop_in.hpp"
#include "core/median.hpp"
#include "query/ray.hpp"

namespace bpaccel {
namespace {

using Clock = std::chrono::steady_clock;
using Proxies = std::vector<const btBroadphaseProxy*>;

// Keeps every proxy the broad phase gives it, as a game's callback would use them.
struct ProxyCollector final : btBroadphaseRayCallback {
  ProxyCollector(const RayQuery& ray, Proxies& out) : out_(out) { aimRay(*this, ray); }
  bool process(const btBroadphaseProxy* proxy) override {
    out_.push_back(proxy);
    return true;
  }

 private:
  Proxies& out_;
};

struct Segment {
  RayQuery ray;
  btVector3 to;
};

// Segments from a random point of the cube in a random direction, 1 to a cube's edge long.
std::vector<Segment> framesRays(std::size_t count, float edge, std::mt19937& rng) {
  std::uniform_real_distribution<float> inside(0, edge), length(1, edge);
  std::normal_distribution<float> gauss;
  std::vector<Segment> rays;
  for (std::size_t k = 0; k < count; ++k) {
    const std::array<float, 3> from{inside(rng), inside(rng), inside(rng)};
    std::array<float, 3> dir{gauss(rng), gauss(rng), gauss(rng)};
    const float norm = std::max(1e-6f, std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]));
    const float l = length(rng);
    const std::array<float, 3> to{from[0] + dir[0] / norm * l, from[1] + dir[1] / norm * l,
                                  from[2] + dir[2] / norm * l};
    rays.push_back({RayQuery::segment(from, to), btVector3(to[0], to[1], to[2])});
  }
  return rays;
}

// Each ray's proxies against Bullet's test on every proxy of the world.
void checkRays(btCollisionWorld& world, const std::vector<Segment>& rays, std::vector<Proxies>& got,
               StepTimes& times) {
  const auto& objects = world.getCollisionObjectArray();
  Proxies exact;
  for (std::size_t r = 0; r < rays.size(); ++r) {
    exact.clear();
    for (int k = 0; k < objects.size(); ++k) {
      const btBroadphaseProxy* p = objects[k]->getBroadphaseHandle();
      const Aabb box{{p->m_aabbMin.x(), p->m_aabbMin.y(), p->m_aabbMin.z()},
                     {p->m_aabbMax.x(), p->m_aabbMax.y(), p->m_aabbMax.z()}};
      if (rayMeetsBox(rays[r].ray, box, rays[r].ray.lambdaMax)) exact.push_back(p);
    }
    std::sort(exact.begin(), exact.end());
    Proxies& mine = got[r];
    std::sort(mine.begin(), mine.end());
    Proxies diff;
    std::set_difference(mine.begin(), mine.end(), exact.begin(), exact.end(), std::back_inserter(diff));
    times.rayExtra += diff.size();
    diff.clear();
    std::set_difference(exact.begin(), exact.end(), mine.begin(), mine.end(), std::back_inserter(diff));
    times.rayMissing += diff.size();
    times.rayHits += mine.size();
  }
}

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

double StepTimes::median() const {
  if (stepSeconds.empty()) throw std::logic_error("StepTimes::median: no frame was timed");
  return bpaccel::median(stepSeconds);
}

StepTimes timeWholeSteps(const SceneConfig& scene, const BtBroadphaseFactory& makeBroadphase,
                         const WholeStepConfig& config) {
  BouncingCubeScene world(scene, makeBroadphase());
  for (std::size_t f = 0; f < config.warmup; ++f) world.step();
  btBroadphaseInterface& broadphase = *world.world().getBroadphase();
  std::mt19937 rng(scene.seed);
  StepTimes times;
  times.stepSeconds.reserve(config.frames);
  std::vector<Proxies> got(config.rays);
  for (std::size_t f = 0; f < config.frames; ++f) {
    const auto start = Clock::now();
    world.step();
    times.stepSeconds.push_back(since(start));
    if (!config.rays) continue;
    const std::vector<Segment> rays = framesRays(config.rays, world.cubeEdge(), rng);
    for (auto& g : got) g.clear();
    const auto castStart = Clock::now();
    for (std::size_t r = 0; r < rays.size(); ++r) {
      ProxyCollector collector(rays[r].ray, got[r]);
      const auto& from = rays[r].ray.from;
      broadphase.rayTest(btVector3(from[0], from[1], from[2]), rays[r].to, collector);
    }
    times.raySeconds.push_back(since(castStart));
    checkRays(world.world(), rays, got, times);
  }
  return times;
}

}  // namespace bpaccel
