// A row of spheres in bpaccel::BroadPhaseManager (the accelerator's C++ model
// as backend), used through FCL's own interface and FCL's default callback.
// Exits 0 when it reports exactly the neighbours that touch.
#include <cstdio>
#include <memory>
#include <vector>

#include <fcl/broadphase/default_broadphase_callbacks.h>
#include <fcl/geometry/shape/sphere.h>

#include <bpaccel/device/built_device.hpp>
#include <bpaccel/device/model_backend.hpp>
#include <bpaccel/fcl/broad_phase_manager.hpp>

int main() {
  // In place of `fcl::DynamicAABBTreeCollisionManagerd manager;`:
  bpaccel::BroadPhaseManagerd manager(std::make_unique<bpaccel::ModelBackend>(bpaccel::builtDeviceParams()));
  fcl::BroadPhaseCollisionManagerd& fclManager = manager;

  // Radius 1, centres 1.5 apart: each sphere overlaps its neighbours only.
  const int count = 20;
  auto sphere = std::make_shared<fcl::Sphered>(1.0);
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  for (int i = 0; i < count; ++i) {
    fcl::Transform3d pose = fcl::Transform3d::Identity();
    pose.translation() = fcl::Vector3d(1.5 * i, 0, 0);
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(sphere, pose));
    fclManager.registerObject(objects.back().get());
  }
  fclManager.setup();

  fcl::DefaultCollisionData<double> data;
  data.request.num_max_contacts = 1000;
  fclManager.collide(&data, fcl::DefaultCollisionFunction<double>);
  const std::size_t contacts = data.result.numContacts();
  const bool ok = contacts == static_cast<std::size_t>(count - 1);
  std::printf("fcl_scene: %d spheres, %zu contacts (expected %d): %s\n", count, contacts, count - 1,
              ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
