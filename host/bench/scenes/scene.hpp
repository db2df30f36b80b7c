#pragma once
// The benchmark's world: objects bouncing in an enclosed cube, simulated by Bullet.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>

#include "core/types.hpp"

class btDiscreteDynamicsWorld;
class btDefaultCollisionConfiguration;
class btCollisionDispatcher;
class btSequentialImpulseConstraintSolver;
class btCollisionShape;
class btRigidBody;

namespace bpaccel {

struct SceneConfig {
  std::size_t objects = 100;
  float minSize = 0.5f;      // smallest object extent (diameter or edge)
  float maxSize = 2.0f;      // largest
  float density = 0.05f;     // objects per unit volume; sets the cube's edge
  float maxSpeed = 10.0f;    // units per second, each component
  float maxSpin = 3.0f;      // radians per second, each component
  float timeStep = 1.0f / 60.0f;
  std::uint32_t seed = 1;

  float cubeEdge() const;
};

/// One object as a picture needs it.
struct ObjectPose {
  std::string shape;                 // sphere, box, cylinder, capsule
  std::array<float, 3> position;
  std::array<float, 4> rotation;     // quaternion x, y, z, w
  std::array<float, 3> halfExtents;  // box: half edges; sphere: radius in [0]; cylinder/capsule: radius, half height
};

/// A Bullet 3 btDiscreteDynamicsWorld: six static walls around a cube and n
/// objects (spheres, boxes, cylinders, capsules) of random sizes, placed and
/// set moving at random from the seed, with no gravity, no damping and
/// restitution 1, so they keep bouncing off each other and the walls.
class BouncingCubeScene {
 public:
  /// `broadphase` null: btDbvtBroadphase, Bullet's recommended one.
  explicit BouncingCubeScene(const SceneConfig& config, std::unique_ptr<btBroadphaseInterface> broadphase = nullptr);
  ~BouncingCubeScene();
  BouncingCubeScene(const BouncingCubeScene&) = delete;
  BouncingCubeScene& operator=(const BouncingCubeScene&) = delete;

  void step();
  /// The objects' world AABBs from their shapes (walls excluded), index = object.
  void aabbs(std::vector<Aabb>& out) const;
  std::vector<ObjectPose> poses() const;
  std::size_t size() const { return bodies_.size(); }
  float cubeEdge() const { return edge_; }
  /// Total kinetic energy: stays roughly constant when the walls and contacts are elastic.
  double kineticEnergy() const;
  /// The world, for callers that inspect contacts or time whole steps.
  btDiscreteDynamicsWorld& world() { return *world_; }

 private:
  SceneConfig config_;
  float edge_;
  std::unique_ptr<btDefaultCollisionConfiguration> collisionConfig_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btRigidBody>> walls_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::string> kinds_;
};

}  // namespace bpaccel
