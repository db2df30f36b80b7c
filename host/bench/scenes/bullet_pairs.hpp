#pragma once
// Tearing down a Bullet broad phase with many proxies in linear time.

#include <btBulletCollisionCommon.h>

namespace bpaccel {

/// Removes every pair of `cache`, each by its hash, freeing its collision
/// algorithm through `dispatcher`. Call it before removing proxies one by one:
/// btDbvtBroadphase::destroyProxy (and so btCollisionWorld::removeCollisionObject)
/// scans the whole cache for the proxy's pairs, which is O(n * pairs) over a
/// whole teardown (24 s at 100,000 objects, hours at 1,000,000) unless the
/// cache is already empty.
inline void removeAllOverlappingPairs(btOverlappingPairCache& cache, btDispatcher* dispatcher) {
  const btBroadphasePairArray pairs = cache.getOverlappingPairArray();  // a copy: removal reorders the original
  for (int k = 0; k < pairs.size(); ++k) cache.removeOverlappingPair(pairs[k].m_pProxy0, pairs[k].m_pProxy1, dispatcher);
}

}  // namespace bpaccel
