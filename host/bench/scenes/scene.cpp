#include "scene.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

#include <btBulletDynamicsCommon.h>
#include <fmt/format.h>

#include "bullet_pairs.hpp"

namespace bpaccel {

float SceneConfig::cubeEdge() const { return std::cbrt(static_cast<float>(objects) / density); }

BouncingCubeScene::BouncingCubeScene(const SceneConfig& config, std::unique_ptr<btBroadphaseInterface> broadphase)
    : config_(config), edge_(config.cubeEdge()), broadphase_(std::move(broadphase)) {
  if (config.objects == 0) throw std::invalid_argument("scene: at least one object");
  if (!(config.minSize > 0) || !(config.maxSize >= config.minSize))
    throw std::invalid_argument(fmt::format("scene: sizes must satisfy 0 < min <= max, got {} and {}",
                                            config.minSize, config.maxSize));
  if (!(config.density > 0)) throw std::invalid_argument("scene: density must be positive");
  if (edge_ < 2 * config.maxSize)
    throw std::invalid_argument(fmt::format("scene: density {} leaves a cube of edge {} too small for objects of size {}",
                                            config.density, edge_, config.maxSize));

  collisionConfig_ = std::make_unique<btDefaultCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(collisionConfig_.get());
  if (!broadphase_) broadphase_ = std::make_unique<btDbvtBroadphase>();
  solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(),
                                                     collisionConfig_.get());
  world_->setGravity(btVector3(0, 0, 0));

  // Walls: static slabs just outside [0, edge]^3.
  const float e = edge_, h = e / 2, t = 1.0f;
  const btVector3 centres[6] = {{-t / 2, h, h}, {e + t / 2, h, h}, {h, -t / 2, h},
                                {h, e + t / 2, h}, {h, h, -t / 2}, {h, h, e + t / 2}};
  const btVector3 halves[6] = {{t / 2, h + t, h + t}, {t / 2, h + t, h + t}, {h + t, t / 2, h + t},
                               {h + t, t / 2, h + t}, {h + t, h + t, t / 2}, {h + t, h + t, t / 2}};
  for (int w = 0; w < 6; ++w) {
    auto& shape = shapes_.emplace_back(std::make_unique<btBoxShape>(halves[w]));
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shape.get());
    info.m_startWorldTransform.setIdentity();
    info.m_startWorldTransform.setOrigin(centres[w]);
    info.m_restitution = 1;
    info.m_friction = 0;
    auto& wall = walls_.emplace_back(std::make_unique<btRigidBody>(info));
    world_->addRigidBody(wall.get());
  }

  std::mt19937 rng(config.seed);
  auto uni = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
  static const char* kKinds[4] = {"sphere", "box", "cylinder", "capsule"};
  for (std::size_t i = 0; i < config.objects; ++i) {
    const int kind = static_cast<int>(rng() % 4);
    const float size = uni(config.minSize, config.maxSize);
    btCollisionShape* shape = nullptr;
    switch (kind) {
      case 0: shape = new btSphereShape(size / 2); break;
      case 1: shape = new btBoxShape(btVector3(size / 2, uni(0.5f, 1) * size / 2, uni(0.5f, 1) * size / 2)); break;
      case 2: shape = new btCylinderShape(btVector3(size / 4, size / 2, size / 4)); break;
      default: shape = new btCapsuleShape(size / 4, size / 2); break;
    }
    shapes_.emplace_back(shape);
    const float mass = size * size * size;
    btVector3 inertia(0, 0, 0);
    shape->calculateLocalInertia(mass, inertia);
    btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape, inertia);
    const float lo = config.maxSize, hi = e - config.maxSize;
    info.m_startWorldTransform.setIdentity();
    info.m_startWorldTransform.setOrigin(btVector3(uni(lo, hi), uni(lo, hi), uni(lo, hi)));
    info.m_startWorldTransform.setRotation(btQuaternion(uni(0, 6.2832f), uni(0, 3.1416f), uni(0, 6.2832f)));
    info.m_restitution = 1;
    info.m_friction = 0;
    info.m_linearDamping = 0;
    info.m_angularDamping = 0;
    auto& body = bodies_.emplace_back(std::make_unique<btRigidBody>(info));
    const float v = config.maxSpeed, w = config.maxSpin;
    body->setLinearVelocity(btVector3(uni(-v, v), uni(-v, v), uni(-v, v)));
    body->setAngularVelocity(btVector3(uni(-w, w), uni(-w, w), uni(-w, w)));
    body->setActivationState(DISABLE_DEACTIVATION);  // never sleep: keep bouncing
    world_->addRigidBody(body.get());
    kinds_.emplace_back(kKinds[kind]);
  }
}

// The world goes first, while the bodies it holds still exist: its destructor
// destroys each body's proxy in O(1) once the pair cache is empty, whereas
// removeRigidBody one by one searches the world's body list linearly, O(n^2)
// in all (hours at 1,000,000 objects).
BouncingCubeScene::~BouncingCubeScene() {
  removeAllOverlappingPairs(*world_->getBroadphase()->getOverlappingPairCache(), dispatcher_.get());
  world_.reset();
}

void BouncingCubeScene::step() { world_->stepSimulation(config_.timeStep, 1, config_.timeStep); }

void BouncingCubeScene::aabbs(std::vector<Aabb>& out) const {
  out.resize(bodies_.size());
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    btVector3 lo, hi;
    bodies_[i]->getCollisionShape()->getAabb(bodies_[i]->getWorldTransform(), lo, hi);
    out[i] = {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}};
  }
}

std::vector<ObjectPose> BouncingCubeScene::poses() const {
  std::vector<ObjectPose> poses;
  for (std::size_t i = 0; i < bodies_.size(); ++i) {
    const btTransform& t = bodies_[i]->getWorldTransform();
    const btQuaternion q = t.getRotation();
    ObjectPose p{kinds_[i], {t.getOrigin().x(), t.getOrigin().y(), t.getOrigin().z()},
                 {q.x(), q.y(), q.z(), q.w()}, {0, 0, 0}};
    const btCollisionShape* s = bodies_[i]->getCollisionShape();
    if (const auto* box = dynamic_cast<const btBoxShape*>(s)) {
      const btVector3 h = box->getHalfExtentsWithMargin();
      p.halfExtents = {h.x(), h.y(), h.z()};
    } else if (const auto* sphere = dynamic_cast<const btSphereShape*>(s)) {
      p.halfExtents = {sphere->getRadius(), 0, 0};
    } else if (const auto* cyl = dynamic_cast<const btCylinderShape*>(s)) {
      p.halfExtents = {cyl->getRadius(), cyl->getHalfExtentsWithMargin().y(), 0};
    } else if (const auto* cap = dynamic_cast<const btCapsuleShape*>(s)) {
      p.halfExtents = {cap->getRadius(), cap->getHalfHeight(), 0};
    }
    poses.push_back(p);
  }
  return poses;
}

double BouncingCubeScene::kineticEnergy() const {
  double e = 0;
  for (const auto& b : bodies_) e += 0.5 / b->getInvMass() * b->getLinearVelocity().length2();
  return e;
}

}  // namespace bpaccel
