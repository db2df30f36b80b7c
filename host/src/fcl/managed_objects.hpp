#pragma once
// The objects of a BroadPhaseManager: their AABBs as last read, the same as
// float boxes rounded outward, and a query tree over those.

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <fcl/math/bv/AABB.h>
#include <fcl/narrowphase/collision_object.h>
#include <fmt/format.h>

#include "../core/types.hpp"
#include "../query/query_index.hpp"
#include "pair_finder.hpp"

namespace bpaccel {

/// A float box that holds `aabb` grown by `margin` on every side: each bound
/// rounded outward, one float step further where the growing itself rounded.
template <typename S>
Aabb outwardBox(const fcl::AABB<S>& aabb, S margin = 0) {
  Aabb box;
  for (int a = 0; a < 3; ++a) {
    box.min[a] = floatAtOrBelow(static_cast<double>(aabb.min_[a] - margin));
    box.max[a] = floatAtOrAbove(static_cast<double>(aabb.max_[a] + margin));
    if (margin > 0) {
      box.min[a] = std::nextafter(box.min[a], -INFINITY);
      box.max[a] = std::nextafter(box.max[a], INFINITY);
    }
  }
  return box;
}

template <typename S>
class ManagedObjects {
 public:
  using Object = fcl::CollisionObject<S>;

  std::size_t size() const { return objects_.size(); }
  Object* object(std::size_t k) const { return objects_[k]; }
  const std::vector<Object*>& objects() const { return objects_; }
  const std::vector<fcl::AABB<S>>& aabbs() const { return aabbs_; }
  const std::vector<Aabb>& boxes() const { return boxes_; }
  /// The query tree over boxes(), brought up to date here: an update of
  /// every object leaves it to the first collide(object) that needs it.
  QueryIndex& index() {
    if (indexStale_) index_.assign(boxes_);
    indexStale_ = false;
    return index_;
  }
  /// Bumped by every change: what was found from the boxes before is stale.
  std::uint64_t version() const { return version_; }

  void add(Object* object) {
    if (object == nullptr) throw std::invalid_argument("bpaccel::BroadPhaseManager: registerObject: null object");
    checkedAabb(object, "registerObject");  // before anything changes
    if (!position_.emplace(object, static_cast<std::uint32_t>(objects_.size())).second)
      throw std::invalid_argument(
          fmt::format("bpaccel::BroadPhaseManager: object {} is already registered", fmt::ptr(object)));
    objects_.push_back(object);
    aabbs_.emplace_back();
    boxes_.emplace_back();
    read(objects_.size() - 1);
  }

  // The last object takes the removed one's place.
  void remove(Object* object) {
    const auto it = position_.find(object);
    if (it == position_.end())
      throw std::invalid_argument(
          fmt::format("bpaccel::BroadPhaseManager: unregisterObject: object {} is not registered", fmt::ptr(object)));
    const std::uint32_t k = it->second, last = static_cast<std::uint32_t>(objects_.size() - 1);
    position_.erase(it);
    if (k != last) {
      objects_[k] = objects_[last];
      aabbs_[k] = aabbs_[last];
      boxes_[k] = boxes_[last];
      position_[objects_[k]] = k;
      if (!indexStale_) index_.set(k, boxes_[k]);
    }
    objects_.pop_back();
    aabbs_.pop_back();
    boxes_.pop_back();
    if (!indexStale_) index_.erase(last);
    ++version_;
  }

  /// `object`'s AABB; throws std::invalid_argument naming it and `where`
  /// when it has NaN or a min above its max (an AABB never computed).
  static const fcl::AABB<S>& checkedAabb(const Object* object, const char* where) {
    const fcl::AABB<S>& aabb = object->getAABB();
    for (int a = 0; a < 3; ++a) {
      const char* fault = std::isnan(aabb.min_[a]) || std::isnan(aabb.max_[a]) ? "has NaN in its AABB"
                          : aabb.min_[a] > aabb.max_[a]                       ? "has its AABB's min above its max"
                                                                              : nullptr;
      if (fault != nullptr)
        throw std::invalid_argument(fmt::format("bpaccel::BroadPhaseManager: {}: object {} {} on axis {} (min {}, "
                                                "max {})",
                                                where, fmt::ptr(object), fault, a, aabb.min_[a], aabb.max_[a]));
    }
    return aabb;
  }

  /// Reads object k's AABB again.
  void read(std::size_t k) {
    const fcl::AABB<S>& aabb = checkedAabb(objects_[k], "reading a registered object");
    aabbs_[k] = aabb;
    boxes_[k] = outwardBox(aabb);
    if (!indexStale_) index_.set(static_cast<std::uint32_t>(k), boxes_[k]);
    ++version_;
  }

  /// Reads the AABB again if `object` is registered.
  void readIfKnown(const Object* object) {
    if (const auto it = position_.find(object); it != position_.end()) read(it->second);
  }

  /// Reads every AABB again; one with NaN throws before any changes.
  void readAll() {
    for (const Object* o : objects_) checkedAabb(o, "update");
    for (std::size_t k = 0; k < objects_.size(); ++k) {
      aabbs_[k] = objects_[k]->getAABB();
      boxes_[k] = outwardBox(aabbs_[k]);
    }
    indexStale_ = true;
    ++version_;
  }

  void clear() {
    objects_.clear();
    aabbs_.clear();
    boxes_.clear();
    position_.clear();
    index_.clear();
    indexStale_ = false;
    ++version_;
  }

 private:
  std::vector<Object*> objects_;  // in registration order, but for removals
  std::unordered_map<const Object*, std::uint32_t> position_;
  std::vector<fcl::AABB<S>> aabbs_;
  std::vector<Aabb> boxes_;
  QueryIndex index_;  // boxes_ by position, for collide(object)
  bool indexStale_ = false;  // index_ is to be assigned boxes_ before its next use
  std::uint64_t version_ = 0;
};

}  // namespace bpaccel
