#include "pair_cache_sync.hpp"

#include <algorithm>
#include <utility>

#include <BulletCollision/BroadphaseCollision/btOverlappingPairCache.h>

namespace bpaccel {

PairCacheSync::PairCacheSync(btOverlappingPairCache& cache, ProxyOf proxyOf, KeyOf keyOf)
    : cache_(cache), proxyOf_(std::move(proxyOf)), keyOf_(std::move(keyOf)) {}

std::uint64_t PairCacheSync::pairKey(std::uint32_t slotA, std::uint32_t slotB) {
  return static_cast<std::uint64_t>(std::min(slotA, slotB)) << 32 | std::max(slotA, slotB);
}

void PairCacheSync::forget(std::uint32_t slot) {
  std::erase_if(present_, [slot](std::uint64_t key) { return key >> 32 == slot || (key & 0xFFFFFFFFu) == slot; });
}

CacheChanges PairCacheSync::apply(std::span<const std::uint64_t> found, btDispatcher* dispatcher) {
  CacheChanges changes;
  // present_ is what the cache held after the last frame. Other code may have
  // changed the cache since (removed a pair, say): then its count differs and
  // the cache itself is read, so removed pairs come back while they overlap,
  // as with btSimpleBroadphase.
  if (static_cast<std::size_t>(cache_.getNumOverlappingPairs()) != present_.size()) rereadCache();
  // A cache with deferred removal (btSortedOverlappingPairCache) ignores
  // removeOverlappingPair: the broad phase cleans the ended pairs and compacts
  // the array itself, as btDbvtBroadphase::performDeferredRemoval does.
  const bool deferred = cache_.hasDeferredRemoval();
  const auto lower = [this](std::uint64_t key) { return proxyOf_(static_cast<std::uint32_t>(key >> 32)); };
  const auto higher = [this](std::uint64_t key) { return proxyOf_(static_cast<std::uint32_t>(key & 0xFFFFFFFFu)); };
  ended_.clear();
  next_.clear();
  std::size_t i = 0, j = 0;
  while (i < found.size() || j < present_.size()) {
    if (j == present_.size() || (i < found.size() && found[i] < present_[j])) {
      if (cache_.addOverlappingPair(lower(found[i]), higher(found[i])) != nullptr) {
        next_.push_back(found[i]);
        ++changes.added;
      } else {
        ++changes.refused;
      }
      ++i;
    } else if (i == found.size() || present_[j] < found[i]) {
      if (deferred)
        ended_.push_back(present_[j]);
      else
        cache_.removeOverlappingPair(lower(present_[j]), higher(present_[j]), dispatcher);
      ++changes.removed;
      ++j;
    } else {
      next_.push_back(present_[j]);
      ++i;
      ++j;
    }
  }
  present_.swap(next_);
  if (deferred) removeDeferred(dispatcher);
  return changes;
}

void PairCacheSync::rereadCache() {
  const btBroadphasePairArray& array = cache_.getOverlappingPairArray();
  present_.resize(static_cast<std::size_t>(array.size()));
  for (int k = 0; k < array.size(); ++k) present_[static_cast<std::size_t>(k)] = keyOf_(array[k]);
  std::sort(present_.begin(), present_.end());
}

void PairCacheSync::removeDeferred(btDispatcher* dispatcher) {
  btBroadphasePairArray& array = cache_.getOverlappingPairArray();
  int invalid = 0;
  for (int k = 0; k < array.size(); ++k) {
    btBroadphasePair& pair = array[k];
    if (!std::binary_search(ended_.begin(), ended_.end(), keyOf_(pair))) continue;
    cache_.cleanOverlappingPair(pair, dispatcher);
    pair.m_pProxy0 = nullptr;
    pair.m_pProxy1 = nullptr;
    ++invalid;
  }
  // Bullet's pair order puts the emptied pairs last.
  array.quickSort(btBroadphasePairSortPredicate());
  array.resize(array.size() - invalid);
}

}  // namespace bpaccel
