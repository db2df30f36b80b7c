#include "bullet_drop_in.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <type_traits>

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>
#include <fmt/format.h>

#include "../core/keys.hpp"

namespace bpaccel {

// The keys are float32: a double-precision Bullet would round AABBs on the way in.
static_assert(std::is_same_v<btScalar, float>, "bpaccel::BulletDropIn needs single-precision Bullet (btScalar = float)");

struct BulletDropIn::Proxy : btBroadphaseProxy {
  std::uint32_t slot = 0;   // fixed for the storage's life; orders pair changes
  std::uint32_t dense = 0;  // index into boxes_ while live
  bool live = false;
};

namespace {

// Any uid works for the hashed cache; slot + 2 keeps uid order = slot order
// (so each cached pair is (lower slot, higher slot)), as btSimpleBroadphase's handle + 2.
constexpr int kUidOffset = 2;

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string describe(const btBroadphaseProxy* proxy) {
  if (proxy == nullptr) return "new proxy";
  return fmt::format("proxy {} (client object {})", proxy->m_uniqueId, fmt::ptr(proxy->m_clientObject));
}

}  // namespace

void aimRay(btBroadphaseRayCallback& callback, const RayQuery& ray) {
  for (int a = 0; a < 3; ++a) {
    callback.m_rayDirectionInverse[a] = ray.inverseDirection[a];
    callback.m_signs[a] = ray.signs[a];
  }
  callback.m_lambda_max = ray.lambdaMax;
}

BulletDropIn::BulletDropIn(std::unique_ptr<Backend> backend, BulletDropInOptions options, btOverlappingPairCache* pairCache)
    : BulletDropIn(std::move(backend), nullptr, options, pairCache) {}

BulletDropIn::BulletDropIn(const BackendFactory& makeBackend, BulletDropInOptions options,
                       btOverlappingPairCache* pairCache)
    : BulletDropIn(nullptr, &makeBackend, options, pairCache) {}

BulletDropIn::BulletDropIn(std::unique_ptr<Backend> backend, const BackendFactory* makeBackend,
                       BulletDropInOptions options, btOverlappingPairCache* pairCache)
    : options_(options), backend_(std::move(backend)) {
  if (options_.maxProxies == 0 || options_.maxProxies > 0xFFFFFFFEull)
    throw BulletDropInError(fmt::format("bpaccel::BulletDropIn: maxProxies must be in 1..{}, got {}", 0xFFFFFFFEull,
                                      options_.maxProxies));
  if (options_.threads == 0) throw BulletDropInError("bpaccel::BulletDropIn: threads must be at least 1");
  if (makeBackend == nullptr) {
    if (!backend_) throw BulletDropInError("bpaccel::BulletDropIn: no backend given");
    if (options_.threads != 1)
      throw BulletDropInError(fmt::format("bpaccel::BulletDropIn: {} threads need a backend each: pass a backend factory",
                                        options_.threads));
    backendName_ = backend_->name();
    broadPhase_ = std::make_unique<BroadPhase>(*backend_, BroadPhaseConfig{.cellSize = options_.cellSize});
  } else {
    if (!*makeBackend) throw BulletDropInError("bpaccel::BulletDropIn: empty backend factory");
    auto naming = [this, makeBackend]() {
      std::unique_ptr<Backend> b = (*makeBackend)();
      if (!b) throw BulletDropInError("bpaccel::BulletDropIn: the backend factory returned no backend");
      backendName_ = b->name();
      return b;
    };
    broadPhase_ = std::make_unique<BroadPhase>(
        naming, BroadPhaseConfig{.cellSize = options_.cellSize, .threads = options_.threads});
  }
  if (pairCache == nullptr) ownedCache_ = std::make_unique<btHashedOverlappingPairCache>();
  cache_ = pairCache != nullptr ? pairCache : ownedCache_.get();
  cacheSync_ = std::make_unique<PairCacheSync>(
      *cache_, [this](std::uint32_t slot) { return slots_[slot].get(); },
      [this](const btBroadphasePair& pair) { return cachedKey(pair); });
}

// Like Bullet's broad phases, the pairs of proxies still alive are left in the
// cache: a world removes its objects (and their pairs) before it drops the broad phase.
BulletDropIn::~BulletDropIn() = default;

BulletDropIn::Proxy& BulletDropIn::owned(btBroadphaseProxy* proxy, const char* what) const {
  if (proxy == nullptr) throw BulletDropInError(fmt::format("{}: null proxy", what));
  // Only the base class's fields are read before the proxy is known to be ours.
  const long long slot = static_cast<long long>(proxy->m_uniqueId) - kUidOffset;
  if (slot < 0 || slot >= static_cast<long long>(slots_.size()) ||
      slots_[static_cast<std::size_t>(slot)].get() != proxy)
    throw BulletDropInError(fmt::format("{}: {} was not created by this broad phase", what, describe(proxy)));
  Proxy& p = *slots_[static_cast<std::size_t>(slot)];
  if (!p.live) throw BulletDropInError(fmt::format("{}: {} was already destroyed", what, describe(proxy)));
  return p;
}

Aabb BulletDropIn::checkedBox(const btVector3& aabbMin, const btVector3& aabbMax, const Proxy* proxy, const char* what) {
  static constexpr char kAxis[3] = {'x', 'y', 'z'};
  // Tested on keys, not floats: -ffast-math builds may fold isnan and float
  // compares with NaN. NaN keys lie outside [key(-inf), key(+inf)].
  static const std::uint32_t kLowest = floatToKey(-std::numeric_limits<float>::infinity());
  static const std::uint32_t kHighest = floatToKey(std::numeric_limits<float>::infinity());
  auto isNaN = [](std::uint32_t key) { return key < kLowest || key > kHighest; };
  Aabb box{};
  for (int a = 0; a < 3; ++a) {
    const float lo = aabbMin[a], hi = aabbMax[a];
    const std::uint32_t loKey = floatToKey(lo), hiKey = floatToKey(hi);
    if (isNaN(loKey) || isNaN(hiKey))
      throw BulletDropInError(fmt::format("{}: {} has NaN in its AABB on {} (min {}, max {})", what, describe(proxy),
                                        kAxis[a], lo, hi));
    if (loKey > hiKey)
      throw BulletDropInError(fmt::format("{}: {} has min {} > max {} on {}", what, describe(proxy), lo, hi, kAxis[a]));
    box.min[static_cast<std::size_t>(a)] = lo;
    box.max[static_cast<std::size_t>(a)] = hi;
  }
  return box;
}

btBroadphaseProxy* BulletDropIn::createProxy(const btVector3& aabbMin, const btVector3& aabbMax, int /*shapeType*/,
                                           void* userPtr, int collisionFilterGroup, int collisionFilterMask,
                                           btDispatcher* /*dispatcher*/) {
  if (boxes_.size() >= options_.maxProxies)
    throw BulletDropInError(fmt::format("createProxy: this broad phase holds at most {} proxies (BulletDropInOptions::maxProxies)",
                                      options_.maxProxies));
  const Aabb box = checkedBox(aabbMin, aabbMax, nullptr, "createProxy");
  std::uint32_t slot;
  if (!freeSlots_.empty()) {
    slot = freeSlots_.back();
    freeSlots_.pop_back();
  } else {
    slot = static_cast<std::uint32_t>(slots_.size());
    slots_.push_back(std::make_unique<Proxy>());
  }
  Proxy& p = *slots_[slot];
  p.m_aabbMin = aabbMin;
  p.m_aabbMax = aabbMax;
  p.m_clientObject = userPtr;
  p.m_collisionFilterGroup = collisionFilterGroup;
  p.m_collisionFilterMask = collisionFilterMask;
  p.m_uniqueId = static_cast<int>(slot) + kUidOffset;
  p.slot = slot;
  p.dense = static_cast<std::uint32_t>(boxes_.size());
  p.live = true;
  boxes_.push_back(box);
  denseSlot_.push_back(slot);
  queries_.set(slot, box);
  return &p;
}

void BulletDropIn::destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) {
  Proxy& p = owned(proxy, "destroyProxy");
  cache_->removeOverlappingPairsContainingProxy(&p, dispatcher);
  cacheSync_->forget(p.slot);
  // Swap-remove from the dense arrays, moving the last box into the hole.
  const std::uint32_t last = static_cast<std::uint32_t>(boxes_.size() - 1);
  const std::uint32_t movedSlot = denseSlot_[last];
  boxes_[p.dense] = boxes_[last];
  denseSlot_[p.dense] = movedSlot;
  slots_[movedSlot]->dense = p.dense;
  boxes_.pop_back();
  denseSlot_.pop_back();
  p.live = false;
  p.m_clientObject = nullptr;
  freeSlots_.push_back(p.slot);
  queries_.erase(p.slot);
}

void BulletDropIn::setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin, const btVector3& aabbMax,
                         btDispatcher* /*dispatcher*/) {
  Proxy& p = owned(proxy, "setAabb");
  boxes_[p.dense] = checkedBox(aabbMin, aabbMax, &p, "setAabb");
  queries_.set(p.slot, boxes_[p.dense]);
  p.m_aabbMin = aabbMin;
  p.m_aabbMax = aabbMax;
}

void BulletDropIn::getAabb(btBroadphaseProxy* proxy, btVector3& aabbMin, btVector3& aabbMax) const {
  const Proxy& p = owned(proxy, "getAabb");
  aabbMin = p.m_aabbMin;
  aabbMax = p.m_aabbMax;
}

void BulletDropIn::rayTest(const btVector3& rayFrom, const btVector3& /*rayTo*/, btBroadphaseRayCallback& rayCallback,
                           const btVector3& aabbMin, const btVector3& aabbMax) {
  // As btDbvtBroadphase: the ray is the callback's origin, inverse direction,
  // signs and length; rayTo is not read.
  RayQuery ray;
  for (int a = 0; a < 3; ++a) {
    ray.from[a] = rayFrom[a];
    ray.inverseDirection[a] = rayCallback.m_rayDirectionInverse[a];
    ray.signs[a] = rayCallback.m_signs[a];
    ray.grow.min[a] = aabbMin[a];
    ray.grow.max[a] = aabbMax[a];
  }
  ray.lambdaMax = rayCallback.m_lambda_max;
  queries_.rayTest(ray, [&](std::uint32_t slot) {
    rayCallback.process(slots_[slot].get());
    ray.lambdaMax = rayCallback.m_lambda_max;
  });
}

void BulletDropIn::aabbTest(const btVector3& aabbMin, const btVector3& aabbMax, btBroadphaseAabbCallback& callback) {
  const Aabb box{{aabbMin[0], aabbMin[1], aabbMin[2]}, {aabbMax[0], aabbMax[1], aabbMax[2]}};
  queries_.aabbTest(box, [&](std::uint32_t slot) { callback.process(slots_[slot].get()); });
}

void BulletDropIn::calculateOverlappingPairs(btDispatcher* dispatcher) {
  const auto start = Clock::now();
  report_ = BulletDropInReport{};
  report_.proxies = boxes_.size();
  broadPhase_->findPairs(std::span<const Aabb>(boxes_), found_);
  report_.overlaps = found_.size();
  const auto found = Clock::now();
  report_.findSeconds = std::chrono::duration<double>(found - start).count();

  // Pairs as 64-bit keys (lower slot, higher slot), sorted: the backend's
  // pair order never reaches Bullet, and changes go to the cache in one fixed order.
  foundKeys_.resize(found_.size());
  for (std::size_t k = 0; k < found_.size(); ++k)
    foundKeys_[k] = PairCacheSync::pairKey(denseSlot_[found_[k].first], denseSlot_[found_[k].second]);
  std::sort(foundKeys_.begin(), foundKeys_.end());
  const CacheChanges changes = cacheSync_->apply(foundKeys_, dispatcher);
  report_.added = changes.added;
  report_.refused = changes.refused;
  report_.removed = changes.removed;
  report_.cacheSeconds = secondsSince(found);
  report_.totalSeconds = secondsSince(start);
}

std::uint64_t BulletDropIn::cachedKey(const btBroadphasePair& pair) const {
  return PairCacheSync::pairKey(owned(pair.m_pProxy0, "pair cache").slot, owned(pair.m_pProxy1, "pair cache").slot);
}

void BulletDropIn::getBroadphaseAabb(btVector3& aabbMin, btVector3& aabbMax) const {
  aabbMin.setValue(0, 0, 0);
  aabbMax.setValue(0, 0, 0);
  if (boxes_.empty()) return;
  Aabb all = boxes_.front();
  for (const Aabb& b : boxes_)
    for (std::size_t a = 0; a < 3; ++a) {
      all.min[a] = std::min(all.min[a], b.min[a]);
      all.max[a] = std::max(all.max[a], b.max[a]);
    }
  aabbMin.setValue(all.min[0], all.min[1], all.min[2]);
  aabbMax.setValue(all.max[0], all.max[1], all.max[2]);
}

void BulletDropIn::resetPool(btDispatcher* /*dispatcher*/) {
  if (!boxes_.empty()) return;
  cacheSync_->reset();
  slots_.clear();
  freeSlots_.clear();
  queries_.clear();
}

void BulletDropIn::printStats() {
  const RunStats& s = broadPhase_->stats();
  fmt::print("bpaccel::BulletDropIn: backend {} cell size {}, {} proxies, {} cached pairs\n"
             "  last frame: {} overlaps, {} added, {} refused by the filter, {} removed, find {:.6f} s, cache {:.6f} s\n"
             "  all frames: {} runs, {} device cycles, {} hits\n",
             backendName_, options_.cellSize ? fmt::format("{}", *options_.cellSize) : std::string("none"),
             boxes_.size(), cache_->getNumOverlappingPairs(), report_.overlaps, report_.added, report_.refused,
             report_.removed, report_.findSeconds, report_.cacheSeconds, s.runs, s.deviceCycles(), s.hits);
}

}  // namespace bpaccel
