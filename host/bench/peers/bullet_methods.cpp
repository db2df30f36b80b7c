#include "bullet_methods.hpp"
#include "scenes/bullet_pairs.hpp"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <stdexcept>

#include <btBulletCollisionCommon.h>
#include <BulletCollision/BroadphaseCollision/btAxisSweep3.h>
#include <fmt/format.h>

namespace bpaccel {
namespace {

constexpr const char* kBullet = "Bullet 3.24";
// bt32BitAxisSweep3's handles are 32-bit; Bullet asserts fewer than 2^31 - 1.
constexpr std::size_t kAxisSweepHandleLimit = 2147483646;
// Its set-up is Theta(n^2) whatever the creation order: it sorts each axis's
// edge list by adjacent swaps as proxies arrive, and a creation order can
// follow one axis only, so y and z cost their inversions, about n^2/2 swaps
// each. Measured here (2 cores, loaded): 2.9 s at 10,000 objects, 16 s at
// 20,000, 58 s at 40,000; so about 6 min at 100,000 and 10 h at 1,000,000.
constexpr std::size_t kAxisSweepSetupLimit = 50000;

btVector3 lo(const Aabb& b) { return {b.min[0], b.min[1], b.min[2]}; }
btVector3 hi(const Aabb& b) { return {b.max[0], b.max[1], b.max[2]}; }

}  // namespace

std::string BulletMethod::name(Kind kind) {
  switch (kind) {
    case Kind::Dbvt: return "btDbvtBroadphase";
    case Kind::AxisSweep32: return "bt32BitAxisSweep3";
    case Kind::Simple: return "btSimpleBroadphase";
  }
  return "?";
}

BulletMethod::BulletMethod(Kind kind, std::span<const Aabb> initial, float worldMin, float worldMax,
                           btCollisionDispatcher* shared)
    : kind_(kind),
      config_(shared ? nullptr : std::make_unique<btDefaultCollisionConfiguration>()),
      ownDispatcher_(shared ? nullptr : std::make_unique<btCollisionDispatcher>(config_.get())),
      dispatcher_(shared ? shared : ownDispatcher_.get()) {
  const std::size_t count = initial.size();
  switch (kind) {
    case Kind::Dbvt: broadphase_ = std::make_unique<btDbvtBroadphase>(); break;
    case Kind::AxisSweep32:
      // No ray queries here, so no raycast accelerator (an extra Dbvt) to keep up to date.
      broadphase_ = std::make_unique<bt32BitAxisSweep3>(btVector3(worldMin, worldMin, worldMin),
                                                         btVector3(worldMax, worldMax, worldMax),
                                                         static_cast<unsigned>(count + 2), nullptr, true);
      break;
    case Kind::Simple: broadphase_ = std::make_unique<btSimpleBroadphase>(static_cast<int>(count + 2)); break;
  }
  // The sweep inserts each new proxy from the end of every axis's sorted edge
  // list: created in order of min x, the x axis costs almost nothing (y and z
  // cannot be ordered at the same time). The other broad phases do not care.
  std::vector<std::uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  if (kind == Kind::AxisSweep32)
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return initial[a].min[0] < initial[b].min[0]; });
  proxies_.resize(count);
  for (std::uint32_t i : order)
    proxies_[i] = broadphase_->createProxy(lo(initial[i]), hi(initial[i]), BOX_SHAPE_PROXYTYPE,
                                           // index + 1: btSimpleBroadphase skips proxies whose client object is null
                                           reinterpret_cast<void*>(static_cast<std::uintptr_t>(i) + 1),
                                           btBroadphaseProxy::DefaultFilter, btBroadphaseProxy::AllFilter,
                                           dispatcher_);
  broadphase_->calculateOverlappingPairs(dispatcher_);
}

// btDbvtBroadphase allocates every proxy and frees it only in destroyProxy
// (LeakSanitizer reports the rest), so its proxies are destroyed first, after
// its pairs (removeAllOverlappingPairs says why). The sweep (built without a
// raycast accelerator) and the simple broad phase keep their proxies in
// arrays they free themselves; destroying them one by one would cost the
// sweep O(n^2) (each removal moves its edges to the end of every axis). No
// pair holds a collision algorithm: nothing was dispatched.
BulletMethod::~BulletMethod() {
  if (kind_ != Kind::Dbvt) return;
  removeAllOverlappingPairs(*broadphase_->getOverlappingPairCache(), dispatcher_);
  for (btBroadphaseProxy* p : proxies_) broadphase_->destroyProxy(p, dispatcher_);
}

void BulletMethod::update(std::span<const Aabb> boxes) {
  if (boxes.size() != proxies_.size()) throw std::invalid_argument("bullet broadphase: object count changed");
  for (std::size_t i = 0; i < boxes.size(); ++i)
    broadphase_->setAabb(proxies_[i], lo(boxes[i]), hi(boxes[i]), dispatcher_);
  broadphase_->calculateOverlappingPairs(dispatcher_);
}

void BulletMethod::pairs(std::vector<Pair>& out) {
  out.clear();
  const btBroadphasePairArray& array = broadphase_->getOverlappingPairCache()->getOverlappingPairArray();
  out.reserve(static_cast<std::size_t>(array.size()));
  for (int k = 0; k < array.size(); ++k) {
    const auto a = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(array[k].m_pProxy0->m_clientObject) - 1);
    const auto b = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(array[k].m_pProxy1->m_clientObject) - 1);
    out.emplace_back(std::min(a, b), std::max(a, b));
  }
}

std::optional<std::string> axisSweepSkipReason(std::size_t objects) {
  if (objects > kAxisSweepHandleLimit)
    return fmt::format("beyond its 32-bit handle limit ({} proxies)", kAxisSweepHandleLimit);
  if (objects > kAxisSweepSetupLimit)
    return fmt::format("its set-up sorts edges by adjacent swaps, Theta(n^2) on y and z whatever the creation order: "
                       "above {} objects it takes over a minute (about 6 min at 100,000 here)",
                       kAxisSweepSetupLimit);
  return std::nullopt;
}

std::vector<MethodSpec> bulletMethods(double maxAllPairsTests) {
  std::vector<MethodSpec> specs;
  for (auto kind : {BulletMethod::Kind::Dbvt, BulletMethod::Kind::AxisSweep32, BulletMethod::Kind::Simple}) {
    MethodSpec s;
    s.name = BulletMethod::name(kind);
    s.kind = MethodKind::Bullet;
    s.library = kBullet;
    if (kind == BulletMethod::Kind::AxisSweep32)
      s.skipReason = [](const SceneStart& start) { return axisSweepSkipReason(start.boxes.size()); };
    if (kind == BulletMethod::Kind::Simple) s.skipReason = allPairsSkipReason(maxAllPairsTests);
    s.make = [kind](const SceneStart& start) {
      return std::make_unique<BulletMethod>(kind, start.boxes, start.worldMin, start.worldMax);
    };
    specs.push_back(std::move(s));
  }
  return specs;
}

}  // namespace bpaccel
