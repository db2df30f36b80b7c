#include "scene_families.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {
namespace {

constexpr std::array<SceneFamily, 6> kFamilies = {SceneFamily::Cube,  SceneFamily::Sizes, SceneFamily::Clusters,
                                                   SceneFamily::Flat,  SceneFamily::Poles, SceneFamily::Layer};

// The bouncing cube behind the FrameSource interface.
class CubeSource final : public FrameSource {
 public:
  explicit CubeSource(const SceneConfig& config)
      : scene_(config), margin_(2 * config.maxSize + 2) {}  // a box poking through a wall for a step stays inside
  void step() override { scene_.step(); }
  void aabbs(std::vector<Aabb>& out) const override { scene_.aabbs(out); }
  std::array<float, 3> worldLo() const override { return {-margin_, -margin_, -margin_}; }
  std::array<float, 3> worldHi() const override {
    const float hi = scene_.cubeEdge() + margin_;
    return {hi, hi, hi};
  }
  std::optional<double> kineticEnergy() const override { return scene_.kineticEnergy(); }
  std::optional<float> cubeEdge() const override { return scene_.cubeEdge(); }

 private:
  BouncingCubeScene scene_;
  float margin_;
};

// What the kinematic families draw for each object.
struct Draw {
  std::mt19937 rng;
  float uni(float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); }
  float logUni(float lo, float hi) { return std::exp(uni(std::log(lo), std::log(hi))); }
  int pick(int k) { return static_cast<int>(rng() % static_cast<unsigned>(k)); }
  // A body the size of the cube's (0.5 to 2 across, each axis 0.5 to 1 of that).
  std::array<float, 3> cubeLike() {
    const float s = uni(0.5f, 2.0f) / 2;
    return {s * uni(0.5f, 1), s * uni(0.5f, 1), s * uni(0.5f, 1)};
  }
};

// The largest AABB half extent a body reaches on each axis while it turns
// about `spinAxis` (a cos + b sin is at most the hypotenuse).
std::array<float, 3> reach(const std::array<float, 3>& half, int spinAxis) {
  std::array<float, 3> r = half;
  const int i = (spinAxis + 1) % 3, j = (spinAxis + 2) % 3;
  r[i] = r[j] = std::hypot(half[i], half[j]);
  return r;
}

}  // namespace

std::vector<SceneFamily> allSceneFamilies() { return {kFamilies.begin(), kFamilies.end()}; }

std::string_view familyName(SceneFamily family) {
  switch (family) {
    case SceneFamily::Cube: return "cube";
    case SceneFamily::Sizes: return "sizes";
    case SceneFamily::Clusters: return "clusters";
    case SceneFamily::Flat: return "flat";
    case SceneFamily::Poles: return "poles";
    case SceneFamily::Layer: return "layer";
  }
  return "?";
}

std::string_view familyDescription(SceneFamily family) {
  switch (family) {
    case SceneFamily::Cube: return "Bullet's bouncing cube: sizes 0.5 to 2, uniform in a cube, 0.05 objects per unit^3";
    case SceneFamily::Sizes: return "extents 0.1 to 10 (log-uniform, 100x), 5 % points and 5 % flat boxes, in a cube";
    case SceneFamily::Clusters: return "eight dense clumps (0.3 objects per unit^3) and 5 % strays in a mostly empty world";
    case SceneFamily::Flat: return "a level 4 units high, 0.25 objects per unit^2 of floor";
    case SceneFamily::Poles: return "poles and beams 4 to 16 long, 0.1 to 0.4 thick, along x, y or z";
    case SceneFamily::Layer: return "every centre at one height, falling and bouncing together, 0.25 objects per unit^2";
  }
  return "?";
}

SceneFamily parseSceneFamily(const std::string& text) {
  std::string names;
  for (SceneFamily f : kFamilies) {
    if (text == familyName(f)) return f;
    names += fmt::format("{}{}", names.empty() ? "" : ", ", familyName(f));
  }
  throw std::invalid_argument(fmt::format("scene family '{}' is not one of {}", text, names));
}

std::unique_ptr<FrameSource> makeFrameSource(SceneFamily family, const SceneConfig& cube) {
  if (family == SceneFamily::Cube) return std::make_unique<CubeSource>(cube);
  return std::make_unique<KinematicScene>(family, cube.objects, cube.seed, cube.timeStep);
}

KinematicScene::KinematicScene(SceneFamily family, std::size_t objects, std::uint32_t seed, float timeStep)
    : timeStep_(timeStep) {
  if (family == SceneFamily::Cube) throw std::invalid_argument("scene: the cube is not a kinematic family");
  if (objects == 0) throw std::invalid_argument("scene: at least one object");
  place(family, objects, seed);
}

// Each family's bodies: shapes first, then the world from the shapes' reach,
// then the regions and the motion.
void KinematicScene::place(SceneFamily family, std::size_t objects, std::uint32_t seed) {
  Draw d{std::mt19937(seed)};
  bodies_.resize(objects);
  const auto n = static_cast<float>(objects);
  std::array<float, 3> reachMax{};
  for (Body& b : bodies_) {
    b.spinAxis = d.pick(3);
    switch (family) {
      case SceneFamily::Sizes: {
        const float s = d.logUni(0.05f, 5.0f);
        b.half = {s * d.uni(0.5f, 1), s * d.uni(0.5f, 1), s * d.uni(0.5f, 1)};
        const int kind = d.pick(20);
        if (kind == 0) b.half = {0, 0, 0};       // a point
        if (kind == 1) b.half[b.spinAxis] = 0;  // flat: turns in its own plane
        break;
      }
      case SceneFamily::Poles: {
        const int along = d.pick(3);
        const float t = d.uni(0.05f, 0.2f);
        b.half = {t, t * d.uni(0.5f, 1), t * d.uni(0.5f, 1)};
        std::swap(b.half[0], b.half[(along + 1) % 3]);
        b.half[along] = d.uni(2.0f, 8.0f);
        b.spinAxis = along;
        break;
      }
      case SceneFamily::Flat:
      case SceneFamily::Layer:
        b.half = d.cubeLike();
        b.spinAxis = 1;  // yaw
        break;
      default: b.half = d.cubeLike(); break;
    }
    b.spin = d.uni(-3, 3);
    const auto r = reach(b.half, b.spinAxis);
    for (int a = 0; a < 3; ++a) reachMax[a] = std::max(reachMax[a], r[a]);
  }
  // The world and each body's region (where its centre may go).
  const auto cube = [&](float density) {
    const float e = std::max(std::cbrt(n / density), 2 * *std::max_element(reachMax.begin(), reachMax.end()) + 1);
    worldLo_ = {0, 0, 0};
    worldHi_ = {e, e, e};
  };
  const auto floor = [&](float areaDensity, float height) {
    const float l = std::max(std::sqrt(n / areaDensity), 2 * std::max(reachMax[0], reachMax[2]) + 1);
    worldLo_ = {0, 0, 0};
    worldHi_ = {l, std::max(height, 2 * reachMax[1] + 0.5f), l};
  };
  float speed = 5;
  switch (family) {
    case SceneFamily::Sizes: cube(0.02f); break;
    case SceneFamily::Poles: cube(0.01f); break;
    case SceneFamily::Flat: floor(0.25f, 4); break;
    case SceneFamily::Layer:
      floor(0.25f, 12);
      gravity_ = 9.81f;
      break;
    default: speed = 3; break;  // clusters: below
  }
  for (Body& b : bodies_)
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = worldLo_[a] + reachMax[a];
      b.hi[a] = worldHi_[a] - reachMax[a];
    }
  if (family == SceneFamily::Clusters) {
    // Clumps of random weights at 0.3 objects per unit^3; the world about a
    // hundred times their volume; 5 % of the objects stray over all of it.
    constexpr int kClumps = 8;
    std::array<float, kClumps> weight{}, half{};
    for (float& w : weight) w = d.uni(0.5f, 1.5f);
    const float total = std::accumulate(weight.begin(), weight.end(), 0.0f);
    double volume = 0;
    for (int k = 0; k < kClumps; ++k) {
      half[k] = 0.5f * std::cbrt(0.95f * n * weight[k] / total / 0.3f) + reachMax[0];
      volume += std::pow(2.0 * half[k], 3);
    }
    const float e = static_cast<float>(std::cbrt(100 * volume));
    worldLo_ = {0, 0, 0};
    worldHi_ = {e, e, e};
    std::array<std::array<float, 3>, kClumps> centre{};
    for (int k = 0; k < kClumps; ++k)
      for (float& c : centre[k]) c = d.uni(half[k], e - half[k]);
    std::discrete_distribution<int> clump(weight.begin(), weight.end());
    for (Body& b : bodies_) {
      const bool stray = d.pick(20) == 0;
      const int k = clump(d.rng);
      for (int a = 0; a < 3; ++a) {
        b.lo[a] = stray ? reachMax[a] : centre[k][a] - half[k] + reachMax[a];
        b.hi[a] = stray ? e - reachMax[a] : centre[k][a] + half[k] - reachMax[a];
      }
    }
  }
  const float layerHeight = d.uni(0.6f, 0.9f) * worldHi_[1];
  for (Body& b : bodies_) {
    for (int a = 0; a < 3; ++a) {
      b.centre[a] = d.uni(b.lo[a], std::max(b.lo[a], b.hi[a]));
      b.velocity[a] = d.uni(-speed, speed);
    }
    if (family == SceneFamily::Flat) b.velocity[1] *= 0.1f;
    if (family == SceneFamily::Layer) {
      b.centre[1] = layerHeight;  // one height for all, and one vertical motion
      b.velocity[1] = 0;
    }
    b.angle = d.uni(0, 6.2832f);
  }
}

// Constant velocity (the layer also falls), mirrored at the region's walls.
// Every body runs the same arithmetic on its own numbers, so the layer's
// bodies, which share their height and vertical speed, keep sharing them.
void KinematicScene::step() {
  const float dt = timeStep_;
  for (Body& b : bodies_) {
    b.velocity[1] -= gravity_ * dt;
    for (int a = 0; a < 3; ++a) {
      float c = b.centre[a] + b.velocity[a] * dt;
      if (c < b.lo[a]) {
        c = std::min(2 * b.lo[a] - c, b.hi[a]);
        b.velocity[a] = std::abs(b.velocity[a]);
      } else if (c > b.hi[a]) {
        c = std::max(2 * b.hi[a] - c, b.lo[a]);
        b.velocity[a] = -std::abs(b.velocity[a]);
      }
      b.centre[a] = c;
    }
    b.angle += b.spin * dt;
  }
}

std::array<float, 3> turnedHalfExtents(const std::array<float, 3>& half, int spinAxis, float angle) {
  const int s = spinAxis, i = (s + 1) % 3, j = (s + 2) % 3;
  const float cs = std::abs(std::cos(angle)), sn = std::abs(std::sin(angle));
  std::array<float, 3> h{};
  h[s] = half[s];
  h[i] = cs * half[i] + sn * half[j];
  h[j] = sn * half[i] + cs * half[j];
  return h;
}

void KinematicScene::aabbs(std::vector<Aabb>& out) const {
  out.resize(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const Body& b = bodies_[k];
    const std::array<float, 3> h = turnedHalfExtents(b.half, b.spinAxis, b.angle);
    for (int a = 0; a < 3; ++a) {
      // Clamped so that rounding cannot carry a box past the world's bounds.
      out[k].min[a] = std::max(b.centre[a] - h[a], worldLo_[a]);
      out[k].max[a] = std::min(b.centre[a] + h[a], worldHi_[a]);
    }
  }
}

}  // namespace bpaccel
