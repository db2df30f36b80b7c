#pragma once
// The benchmark's scenes beyond the bouncing cube: families of boxes a broad
// phase meets in games and robots, each generated from a seed and moved
// frame by frame without a physics engine (every frame is validated like the
// cube's, so no physics is needed to make them fair).

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/types.hpp"
#include "scene.hpp"

namespace bpaccel {

/// A scene the benchmark runs frame by frame.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame.
  virtual void step() = 0;
  /// This frame's boxes, index = object (the same objects every frame).
  virtual void aabbs(std::vector<Aabb>& out) const = 0;
  /// Bounds that hold every box of every frame, per axis.
  virtual std::array<float, 3> worldLo() const = 0;
  virtual std::array<float, 3> worldHi() const = 0;
  /// Only a physical scene has one (the cube's).
  virtual std::optional<double> kineticEnergy() const { return std::nullopt; }
  /// The cube's edge (the JSON's cube_edge); none for the other families.
  virtual std::optional<float> cubeEdge() const { return std::nullopt; }
};

/// The families: `cube` is the bouncing cube (Bullet's physics, SceneConfig);
/// the others move kinematically (below).
enum class SceneFamily { Cube, Sizes, Clusters, Flat, Poles, Layer };

/// Every family, cube first.
std::vector<SceneFamily> allSceneFamilies();
/// "cube", "sizes", "clusters", "flat", "poles", "layer".
std::string_view familyName(SceneFamily family);
/// The inverse; throws std::invalid_argument naming the text and the names otherwise.
SceneFamily parseSceneFamily(const std::string& text);
/// One line for tables: what the family's boxes are like.
std::string_view familyDescription(SceneFamily family);

/// The scene of `family` with `objects` objects from `seed`. The cube takes
/// the rest of `cube` (sizes, density, speeds); the others use their own.
std::unique_ptr<FrameSource> makeFrameSource(SceneFamily family, const SceneConfig& cube);

/// The half extents of the AABB of a box of half extents `half` turned by
/// `angle` radians about axis `spinAxis`: the two other axes each span |cos|
/// of their own half extent plus |sin| of the other's.
std::array<float, 3> turnedHalfExtents(const std::array<float, 3>& half, int spinAxis, float angle);

/// The kinematic families. Every object is a box of fixed half extents that
/// turns about one axis at its own rate (its AABB grows and shrinks on both
/// sides, as a rotating body's does), moves at constant velocity and bounces
/// off the walls of its region. A region is the world (or, for clusters, the
/// object's clump) shrunk by the family's largest half extent, so every box
/// of every frame stays inside the world's bounds.
///
/// - sizes: half extents log-uniform over 0.05 to 5 (100 times), 5 % of the
///   boxes points (zero extent) and 5 % flat (zero on one axis), in a cube.
/// - clusters: eight clumps of random weights, 0.3 objects per unit^3 inside,
///   their centres spread over a world about a hundred times their volume.
/// - flat: a level 4 units high, 0.25 objects per unit^2 of floor.
/// - poles: half lengths 2 to 8 along x, y or z, half thickness 0.05 to 0.2,
///   turning about their long axis.
/// - layer: every box's centre at the same height, which falls under gravity
///   and bounces on the floor: the vertical axis separates nothing.
class KinematicScene final : public FrameSource {
 public:
  KinematicScene(SceneFamily family, std::size_t objects, std::uint32_t seed, float timeStep = 1.0f / 60.0f);
  void step() override;
  void aabbs(std::vector<Aabb>& out) const override;
  std::array<float, 3> worldLo() const override { return worldLo_; }
  std::array<float, 3> worldHi() const override { return worldHi_; }

 private:
  struct Body {
    std::array<float, 3> centre, velocity, half;  // half: extents before turning
    std::array<float, 3> lo, hi;                  // where the centre may go
    int spinAxis = 1;
    float angle = 0, spin = 0;  // radians, radians per second
  };
  void place(SceneFamily family, std::size_t objects, std::uint32_t seed);
  float timeStep_;
  float gravity_ = 0;  // the layer's, on y
  std::vector<Body> bodies_;
  std::array<float, 3> worldLo_{}, worldHi_{};
};

}  // namespace bpaccel
