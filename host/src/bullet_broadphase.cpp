#include "bullet_broadphase.hpp"

#include <cstdint>
#include <stdexcept>

#include <btBulletCollisionCommon.h>
#include <BulletCollision/BroadphaseCollision/btAxisSweep3.h>

namespace bpaccel {

std::string BulletBroadphase::name(Kind kind) {
  switch (kind) {
    case Kind::Dbvt: return "btDbvtBroadphase";
    case Kind::AxisSweep32: return "bt32BitAxisSweep3";
    case Kind::Simple: return "btSimpleBroadphase";
  }
  return "?";
}

BulletBroadphase::BulletBroadphase(Kind kind, std::span<const Aabb> initial, float worldMin, float worldMax)
    : kind_(kind),
      config_(std::make_unique<btDefaultCollisionConfiguration>()),
      dispatcher_(std::make_unique<btCollisionDispatcher>(config_.get())) {
  const int count = static_cast<int>(initial.size());
  switch (kind) {
    case Kind::Dbvt: broadphase_ = std::make_unique<btDbvtBroadphase>(); break;
    case Kind::AxisSweep32:
      // No ray queries here, so no raycast accelerator (an extra Dbvt) to keep up to date.
      broadphase_ = std::make_unique<bt32BitAxisSweep3>(btVector3(worldMin, worldMin, worldMin),
                                                         btVector3(worldMax, worldMax, worldMax),
                                                         static_cast<unsigned>(count + 2), nullptr, true);
      break;
    case Kind::Simple: broadphase_ = std::make_unique<btSimpleBroadphase>(count + 2); break;
  }
  proxies_.reserve(initial.size());
  for (int i = 0; i < count; ++i) {
    const Aabb& b = initial[static_cast<std::size_t>(i)];
    proxies_.push_back(broadphase_->createProxy(btVector3(b.min[0], b.min[1], b.min[2]),
                                                btVector3(b.max[0], b.max[1], b.max[2]), BOX_SHAPE_PROXYTYPE,
                                                // index + 1: btSimpleBroadphase skips proxies whose client object is null
                                                reinterpret_cast<void*>(static_cast<std::uintptr_t>(i) + 1),
                                                btBroadphaseProxy::DefaultFilter, btBroadphaseProxy::AllFilter,
                                                dispatcher_.get()));
  }
  broadphase_->calculateOverlappingPairs(dispatcher_.get());
}

BulletBroadphase::~BulletBroadphase() {
  for (btBroadphaseProxy* p : proxies_) broadphase_->destroyProxy(p, dispatcher_.get());
}

void BulletBroadphase::update(std::span<const Aabb> boxes) {
  if (boxes.size() != proxies_.size()) throw std::invalid_argument("bullet broadphase: object count changed");
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Aabb& b = boxes[i];
    broadphase_->setAabb(proxies_[i], btVector3(b.min[0], b.min[1], b.min[2]), btVector3(b.max[0], b.max[1], b.max[2]),
                         dispatcher_.get());
  }
  broadphase_->calculateOverlappingPairs(dispatcher_.get());
}

void BulletBroadphase::pairs(std::vector<Pair>& out) const {
  out.clear();
  const btBroadphasePairArray& array = broadphase_->getOverlappingPairCache()->getOverlappingPairArray();
  out.reserve(static_cast<std::size_t>(array.size()));
  for (int k = 0; k < array.size(); ++k) {
    const auto a = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(array[k].m_pProxy0->m_clientObject) - 1);
    const auto b = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(array[k].m_pProxy1->m_clientObject) - 1);
    out.emplace_back(std::min(a, b), std::max(a, b));
  }
}

}  // namespace bpaccel
