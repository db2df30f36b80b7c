#pragma once
// bpaccel::BulletDropIn: a btBroadphaseInterface that Bullet worlds take in
// place of btDbvtBroadphase, finding pairs with BroadPhase on any Backend.

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <BulletCollision/BroadphaseCollision/btBroadphaseInterface.h>
#include <BulletCollision/BroadphaseCollision/btBroadphaseProxy.h>

#include "../device/backend.hpp"
#include "pair_cache_sync.hpp"
#include "../broad_phase/broad_phase.hpp"
#include "../core/types.hpp"
#include "../query/query_index.hpp"

class btOverlappingPairCache;

namespace bpaccel {

/// Gives a broad-phase ray callback the ray's inverse direction, signs and
/// length (the fields btCollisionWorld::rayTest sets for its own), for a
/// broad-phase rayTest of any btBroadphaseInterface; with RayQuery::segment,
/// the ray between two points.
void aimRay(btBroadphaseRayCallback& callback, const RayQuery& ray);

/// Misuse of the broad phase (bad AABB, too many proxies, a foreign or
/// destroyed proxy); the message names the proxy and the reason.
class BulletDropInError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct BulletDropInOptions {
  /// k-d tree cell size; none = the whole scene is one cell (chunked to the backend's capacity).
  std::optional<std::size_t> cellSize = 64;
  /// Most live proxies; createProxy beyond it throws. Indices are 32-bit, so never more than 2^32 - 2.
  std::uint64_t maxProxies = 0xFFFFFFFEull;
  /// Threads sharing the k-d tree's cells; more than one needs a backend factory.
  std::size_t threads = 1;
};

/// What the last calculateOverlappingPairs did and spent (steady clock).
struct BulletDropInReport {
  std::size_t proxies = 0;
  std::size_t overlaps = 0;         // overlapping proxy pairs found (before the cache's filter)
  std::size_t added = 0;            // pairs that began to overlap and that the cache took
  std::size_t refused = 0;          // overlapping pairs the cache's filter refused (offered every frame)
  std::size_t removed = 0;          // removeOverlappingPair calls for pairs that ended
  double findSeconds = 0;           // BroadPhase::findPairs (host and backend)
  double cacheSeconds = 0;          // ordering the pairs, diffing with the cache, add/remove calls
  double totalSeconds = 0;
};

/// The pair cache holds exactly the pairs whose AABBs, as last given to
/// createProxy/setAabb, overlap (inclusively, touching counts) and that the
/// cache's filter accepts (collision filter group and mask, or the user's
/// btOverlapFilterCallback; Bullet's worlds give static objects a group and
/// mask that exclude static-versus-static pairs). Each calculateOverlappingPairs
/// adds the pairs that began to overlap and removes those that ended, in
/// ascending order of the proxies' creation slots: the order btSimpleBroadphase
/// applies its changes in, so a world steps bit-identically with either.
/// btDbvtBroadphase instead keeps pairs of enlarged AABBs and removes them
/// lazily: its cache holds more pairs, but the same ones get contact points.
///
/// Proxies are owned here: their storage lives as long as the broad phase and
/// is reused (last freed, first reused) by later createProxy calls.
class BulletDropIn final : public btBroadphaseInterface {
 public:
  /// `pairCache` null: a btHashedOverlappingPairCache owned here. Otherwise the
  /// caller's cache, which must outlive this broad phase and hold only its proxies.
  explicit BulletDropIn(std::unique_ptr<Backend> backend, BulletDropInOptions options = {},
                      btOverlappingPairCache* pairCache = nullptr);
  /// `options.threads` workers, each with a backend of its own from `makeBackend`.
  explicit BulletDropIn(const BackendFactory& makeBackend, BulletDropInOptions options = {},
                      btOverlappingPairCache* pairCache = nullptr);
  ~BulletDropIn() override;
  BulletDropIn(const BulletDropIn&) = delete;
  BulletDropIn& operator=(const BulletDropIn&) = delete;

  btBroadphaseProxy* createProxy(const btVector3& aabbMin, const btVector3& aabbMax, int shapeType, void* userPtr,
                                 int collisionFilterGroup, int collisionFilterMask, btDispatcher* dispatcher) override;
  void destroyProxy(btBroadphaseProxy* proxy, btDispatcher* dispatcher) override;
  void setAabb(btBroadphaseProxy* proxy, const btVector3& aabbMin, const btVector3& aabbMax,
               btDispatcher* dispatcher) override;
  void getAabb(btBroadphaseProxy* proxy, btVector3& aabbMin, btVector3& aabbMax) const override;
  /// Every proxy whose AABB, grown by the ray's box (aabbMin, aabbMax), the ray
  /// meets within the callback's m_lambda_max (btDbvtBroadphase's test,
  /// btRayAabb2, on the exact AABBs), read again after each process() call:
  /// a callback may shorten the ray as it goes. Served by a tree over the
  /// proxies (QueryIndex), rebuilt when they have changed.
  void rayTest(const btVector3& rayFrom, const btVector3& rayTo, btBroadphaseRayCallback& rayCallback,
               const btVector3& aabbMin = btVector3(0, 0, 0), const btVector3& aabbMax = btVector3(0, 0, 0)) override;
  /// Every proxy whose AABB overlaps the box (inclusively), from the same tree.
  void aabbTest(const btVector3& aabbMin, const btVector3& aabbMax, btBroadphaseAabbCallback& callback) override;
  void calculateOverlappingPairs(btDispatcher* dispatcher) override;
  btOverlappingPairCache* getOverlappingPairCache() override { return cache_; }
  const btOverlappingPairCache* getOverlappingPairCache() const override { return cache_; }
  /// The union of all proxies' AABBs; a zero box when there is none.
  void getBroadphaseAabb(btVector3& aabbMin, btVector3& aabbMax) const override;
  /// With no live proxy, forgets the slot history so ids and order start over.
  void resetPool(btDispatcher* dispatcher) override;
  /// Proxies, pairs, backend and the last frame's report, on stdout.
  void printStats() override;

  std::size_t proxyCount() const { return boxes_.size(); }
  const BulletDropInReport& lastFrame() const { return report_; }
  /// The backend's name (cpu, model, rtl).
  const std::string& backendName() const { return backendName_; }
  /// The index rayTest and aabbTest use (by proxy slot, m_uniqueId - 2); prepare() builds it ahead of a query.
  QueryIndex& queryIndex() { return queries_; }
  /// Statistics of the pair finding, summed over all frames.
  const RunStats& runStats() const { return broadPhase_->stats(); }

 private:
  struct Proxy;
  Proxy& owned(btBroadphaseProxy* proxy, const char* what) const;
  std::uint64_t cachedKey(const btBroadphasePair& pair) const;
  static Aabb checkedBox(const btVector3& aabbMin, const btVector3& aabbMax, const Proxy* proxy, const char* what);

  BulletDropIn(std::unique_ptr<Backend> backend, const BackendFactory* makeBackend,
             BulletDropInOptions options, btOverlappingPairCache* pairCache);

  BulletDropInOptions options_;
  std::string backendName_;
  std::unique_ptr<Backend> backend_;         // the one backend, unless a factory makes them
  std::unique_ptr<BroadPhase> broadPhase_;
  std::unique_ptr<btOverlappingPairCache> ownedCache_;
  btOverlappingPairCache* cache_;
  std::vector<std::unique_ptr<Proxy>> slots_;   // by slot; storage kept after destroyProxy
  std::vector<std::uint32_t> freeSlots_;        // destroyed slots, the last one reused first
  std::vector<Aabb> boxes_;                     // live proxies' boxes, dense (what BroadPhase sees)
  std::vector<std::uint32_t> denseSlot_;        // slot of each dense box
  // Pairs of slots as keys (lower << 32 | higher), sorted.
  std::vector<Pair> found_;                     // this frame's pairs, dense indices
  std::vector<std::uint64_t> foundKeys_;        // the same as slot keys (PairCacheSync::pairKey), sorted
  std::unique_ptr<PairCacheSync> cacheSync_;    // the cache brought to each frame's pairs
  QueryIndex queries_;                          // the live proxies' boxes by slot, for rayTest and aabbTest
  BulletDropInReport report_;
};

}  // namespace bpaccel
