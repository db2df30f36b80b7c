#include "fcl_managers.hpp"

#include <algorithm>
#include <stdexcept>

#include <fcl/broadphase/broadphase_SaP.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/broadphase/broadphase_spatialhash.h>
#include <fcl/broadphase/detail/sparse_hash_table.h>
#include <fcl/geometry/shape/box.h>
#include <fmt/format.h>

#include "device/cpu_backend.hpp"
#include "fcl/broad_phase_manager.hpp"

namespace bpaccel {
namespace {

// A collision object whose world AABB is set directly, as Bullet's setAabb
// does, so FCL and Bullet start from the same boxes (FCL would otherwise
// compute it from a shape and a transform).
class AabbObject : public fcl::CollisionObjectd {
 public:
  AabbObject(const std::shared_ptr<fcl::CollisionGeometryd>& shape, std::uint32_t index)
      : fcl::CollisionObjectd(shape), index_(index) {}
  void setAabb(const Aabb& b) {
    aabb.min_ = {b.min[0], b.min[1], b.min[2]};
    aabb.max_ = {b.max[0], b.max[1], b.max[2]};
  }
  std::uint32_t index() const { return index_; }

 private:
  std::uint32_t index_;
};

bool recordPair(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  const auto i = static_cast<AabbObject*>(a)->index(), j = static_cast<AabbObject*>(b)->index();
  static_cast<std::vector<Pair>*>(data)->emplace_back(std::min(i, j), std::max(i, j));
  return false;  // go on: every pair
}

}  // namespace

struct FclManager::Impl {
  std::shared_ptr<fcl::CollisionGeometryd> shape = std::make_shared<fcl::Boxd>(1, 1, 1);
  std::vector<std::unique_ptr<AabbObject>> objects;
  std::vector<fcl::CollisionObjectd*> raw;  // the same objects, as the manager takes them
  std::unique_ptr<fcl::BroadPhaseCollisionManagerd> manager;
  Usage usage = Usage::UpdateAll;
};

FclManager::FclManager(Kind kind, Usage usage, const SceneStart& start, std::size_t bpaccelCellSize)
    : impl_(std::make_unique<Impl>()) {
  impl_->usage = usage;
  switch (kind) {
    case Kind::DynamicAabbTree:
      impl_->manager = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
      break;
    case Kind::SweepAndPrune:
      // FCL 0.7.0's SaPCollisionManager::update_ moves a box's max end point
      // only in the direction its min end point moved: a box that grows or
      // shrinks on both sides (the AABB of a rotating object) corrupts its
      // lists and crashes. So it is rebuilt every frame: registerObjects sorts
      // the end points and sweeps, which is the manager's batch use.
      impl_->manager = std::make_unique<fcl::SaPCollisionManagerd>();
      impl_->usage = Usage::Rebuild;
      break;
    case Kind::Bpaccel:
      impl_->manager = std::make_unique<BroadPhaseManagerd>(
          std::make_unique<CpuBackend>(),
          BroadPhaseManagerOptions{.cellSize = bpaccelCellSize, .partition = PartitionKind::UniformGrid});
      break;
    case Kind::SpatialHashing: {
      // Cells as large as the largest box, so a box touches at most 8 cells
      // (FCL documents no choice; this is the usual one for spatial hashing).
      // FCL reports every two objects that share a cell, without an AABB test:
      // those are its extra pairs.
      double largest = 0;
      for (const Aabb& b : start.boxes)
        for (int a = 0; a < 3; ++a) largest = std::max(largest, static_cast<double>(b.max[a] - b.min[a]));
      const fcl::Vector3d lo(start.worldMin, start.worldMin, start.worldMin);
      const fcl::Vector3d hi(start.worldMax, start.worldMax, start.worldMax);
      // The sparse (unordered_map) table, as FCL's own broad-phase tests use it:
      // the default dense table has 1000 bins whatever the scene.
      using Table = fcl::detail::SparseHashTable<fcl::AABBd, fcl::CollisionObjectd*, fcl::detail::SpatialHash<double>>;
      impl_->manager =
          std::make_unique<fcl::SpatialHashingCollisionManager<double, Table>>(std::max(largest, 1e-3), lo, hi);
      break;
    }
  }
  for (std::size_t i = 0; i < start.boxes.size(); ++i) {
    auto& o = impl_->objects.emplace_back(std::make_unique<AabbObject>(impl_->shape, static_cast<std::uint32_t>(i)));
    o->setAabb(start.boxes[i]);
    impl_->raw.push_back(o.get());
  }
  impl_->manager->registerObjects(impl_->raw);
  impl_->manager->setup();
}

FclManager::~FclManager() = default;

void FclManager::update(std::span<const Aabb> boxes) {
  if (boxes.size() != impl_->objects.size()) throw std::invalid_argument("fcl: object count changed");
  for (std::size_t i = 0; i < boxes.size(); ++i) impl_->objects[i]->setAabb(boxes[i]);
  switch (impl_->usage) {
    case Usage::UpdateAll: impl_->manager->update(); break;
    case Usage::UpdateEach: impl_->manager->update(impl_->raw); break;
    case Usage::Rebuild:
      impl_->manager->clear();
      impl_->manager->registerObjects(impl_->raw);
      impl_->manager->setup();
      break;
  }
  pairs_.clear();
  impl_->manager->collide(&pairs_, recordPair);
}

namespace {

MethodSpec fclSpec(std::string name, FclManager::Kind kind, FclManager::Usage usage) {
  MethodSpec s;
  s.name = std::move(name);
  s.kind = MethodKind::Peer;
  s.library = "FCL 0.7";
  s.make = [kind, usage](const SceneStart& start) { return std::make_unique<FclManager>(kind, usage, start); };
  return s;
}

}  // namespace

std::vector<MethodSpec> fclMethods(double maxSweepTests) {
  using K = FclManager::Kind;
  using U = FclManager::Usage;
  std::vector<MethodSpec> specs = {
      fclSpec("FCL DynamicAABBTree", K::DynamicAabbTree, U::UpdateAll),
      fclSpec("FCL DynamicAABBTree, update(objects)", K::DynamicAabbTree, U::UpdateEach),
      fclSpec("FCL DynamicAABBTree, rebuilt", K::DynamicAabbTree, U::Rebuild),
      fclSpec("FCL SaP (rebuilt)", K::SweepAndPrune, U::Rebuild),
      fclSpec("FCL SpatialHashing", K::SpatialHashing, U::UpdateAll)};
  // Its set-up and every frame are one registerObjects: a sweep that
  // max-method-seconds cannot stop midway.
  specs[3].skipReason = sweepSkipReason(maxSweepTests);
  return specs;
}

MethodSpec bpaccelFclMethod(std::size_t cellSize) {
  MethodSpec s = fclSpec(fmt::format("bpaccel::BroadPhaseManager, cpu grid {}", cellSize), FclManager::Kind::Bpaccel,
                         FclManager::Usage::UpdateAll);
  s.kind = MethodKind::Cpu;
  s.library = "bpaccel";
  s.cellSize = cellSize;
  s.partition = partitionName(PartitionKind::UniformGrid);
  s.make = [cellSize](const SceneStart& start) {
    return std::make_unique<FclManager>(FclManager::Kind::Bpaccel, FclManager::Usage::UpdateAll, start, cellSize);
  };
  return s;
}

}  // namespace bpaccel
