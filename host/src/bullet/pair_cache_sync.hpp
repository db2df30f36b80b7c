#pragma once
// Keeps a Bullet pair cache equal to the pairs a frame found: the pairs that
// began are added and those that ended removed, in ascending order of their
// keys, whatever order the broad phase found them in.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

class btBroadphaseProxy;
class btDispatcher;
class btOverlappingPairCache;
struct btBroadphasePair;

namespace bpaccel {

/// What one frame changed in the cache.
struct CacheChanges {
  std::size_t added = 0;    // pairs that began to overlap and that the cache took
  std::size_t refused = 0;  // overlapping pairs the cache's filter refused (offered every frame)
  std::size_t removed = 0;  // pairs that ended
};

class PairCacheSync {
 public:
  /// The proxy of a slot, and the key of a cached pair (pairKey of its proxies' slots).
  using ProxyOf = std::function<btBroadphaseProxy*(std::uint32_t slot)>;
  using KeyOf = std::function<std::uint64_t(const btBroadphasePair& pair)>;
  PairCacheSync(btOverlappingPairCache& cache, ProxyOf proxyOf, KeyOf keyOf);

  /// A pair of slots as one key: lower slot << 32 | higher slot.
  static std::uint64_t pairKey(std::uint32_t slotA, std::uint32_t slotB);
  /// Brings the cache to `found` (this frame's pairs as keys, sorted). A
  /// pair the cache's filter refuses is offered again next frame, as
  /// btSimpleBroadphase does; pairs another party removed from the cache come
  /// back while they overlap.
  CacheChanges apply(std::span<const std::uint64_t> found, btDispatcher* dispatcher);
  /// Forgets the pairs of a slot whose proxy left (and took its pairs from the cache).
  void forget(std::uint32_t slot);
  /// Forgets what the cache held (the pool is reset with no live proxy).
  void reset() { present_.clear(); }

 private:
  void rereadCache();
  void removeDeferred(btDispatcher* dispatcher);

  btOverlappingPairCache& cache_;
  ProxyOf proxyOf_;
  KeyOf keyOf_;
  std::vector<std::uint64_t> present_;  // the cache's pairs after the last frame, sorted
  std::vector<std::uint64_t> next_;     // present_ being rebuilt
  std::vector<std::uint64_t> ended_;    // pairs to drop from a cache with deferred removal
};

}  // namespace bpaccel
