// Boxes dropped on a floor in a Bullet world whose broad phase is
// bpaccel::BulletDropIn (the accelerator's C++ model as backend). Exits 0 when
// every box comes to rest on the floor, which needs every box-floor and
// box-box pair found.
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <btBulletDynamicsCommon.h>

#include <bpaccel/device/built_device.hpp>
#include <bpaccel/device/model_backend.hpp>
#include <bpaccel/bullet/bullet_drop_in.hpp>

int main() {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  // In place of `btDbvtBroadphase broadphase;`:
  bpaccel::BulletDropIn broadphase(
      std::make_unique<bpaccel::ModelBackend>(bpaccel::builtDeviceParams()));
  btSequentialImpulseConstraintSolver solver;
  btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, -10, 0));

  btBoxShape floorShape(btVector3(50, 1, 50));
  btRigidBody floor(btRigidBody::btRigidBodyConstructionInfo(0, nullptr, &floorShape));
  floor.getWorldTransform().setOrigin(btVector3(0, -1, 0));
  world.addRigidBody(&floor);

  btBoxShape boxShape(btVector3(0.5f, 0.5f, 0.5f));
  btVector3 inertia;
  boxShape.calculateLocalInertia(1, inertia);
  std::vector<std::unique_ptr<btRigidBody>> boxes;
  for (int x = 0; x < 4; ++x)
    for (int level = 0; level < 3; ++level) {
      btRigidBody::btRigidBodyConstructionInfo info(1, nullptr, &boxShape, inertia);
      info.m_startWorldTransform.setIdentity();
      info.m_startWorldTransform.setOrigin(btVector3(x * 1.5f, 2.0f + level * 1.5f, 0));
      boxes.push_back(std::make_unique<btRigidBody>(info));
      world.addRigidBody(boxes.back().get());
    }

  for (int frame = 0; frame < 240; ++frame) world.stepSimulation(1.0f / 60, 1, 1.0f / 60);

  int failures = 0;
  for (const auto& box : boxes) {
    const btVector3 p = box->getWorldTransform().getOrigin();
    // Stacks of three: the centre rests at 0.5, 1.5 or 2.5 above the floor.
    const float level = p.y() - 0.5f;
    if (std::fabs(level - std::round(level)) > 0.05f || level < -0.05f || level > 2.05f) {
      std::printf("box at (%.3f, %.3f, %.3f) is not resting on the floor or a box\n", p.x(), p.y(), p.z());
      ++failures;
    }
  }
  std::printf("bullet_world: %zu boxes, %d pairs cached, backend %s: %s\n", boxes.size(),
              broadphase.getOverlappingPairCache()->getNumOverlappingPairs(), broadphase.backendName().c_str(),
              failures == 0 ? "all at rest" : "FAILED");
  for (const auto& box : boxes) world.removeRigidBody(box.get());
  world.removeRigidBody(&floor);
  return failures == 0 ? 0 : 1;
}
