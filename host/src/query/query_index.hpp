#pragma once
// Ray and box queries over a set of boxes that changes between them.

#include <cstdint>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "box_tree.hpp"
#include "ray.hpp"

namespace bpaccel {

/// The boxes of a scene, each known by an id (ids index a vector: keep them
/// dense), and the tree that answers queries on them. Changes are cheap and
/// the tree is rebuilt when a query needs it: a box set or erased since the
/// last build is left out of the tree's answers, and the boxes set since are
/// tested one by one, until more than 64 + size()/64 of them have changed;
/// then the next query (or prepare()) rebuilds the tree first. So a frame
/// that moves every box pays one build (linear in the boxes) before its first
/// query, and a few changes between queries cost no build at all.
///
/// Answers are exactly Bullet's: rayTest reports every box that rayMeetsBox
/// accepts, aabbTest every box that boxesOverlap, for any input (NaN and
/// infinities included). Not thread-safe; one index per thread, or a lock.
class QueryIndex {
 public:
  /// Boxes 0 .. n-1, replacing every other. Throws std::invalid_argument
  /// naming the first box with NaN or min > max.
  void assign(std::span<const Aabb> boxes);
  /// Adds box `id` or moves it; the same check.
  void set(std::uint32_t id, const Aabb& box);
  /// Throws std::invalid_argument when `id` holds no box.
  void erase(std::uint32_t id);
  void clear();
  bool contains(std::uint32_t id) const { return id < flags_.size() && (flags_[id] & kLive); }
  std::size_t size() const { return live_; }

  /// Calls hit(id) for each box the ray meets (rayMeetsBox with the ray's
  /// lambdaMax as it stands when that box is tested: `hit` may shorten it).
  void rayTest(RayQuery& ray, const QueryHit& hit);
  /// Calls hit(id) for each box that overlaps `box` (boxesOverlap).
  void aabbTest(const Aabb& box, const QueryHit& hit);
  /// Rebuilds the tree now if a query would: to take the build out of the first query's time.
  void prepare();
  /// Trees built so far.
  std::uint64_t builds() const { return builds_; }
  /// Boxes tested one by one by each query until the next build.
  std::size_t loose() const { return loose_.size(); }

 private:
  static constexpr std::uint8_t kLive = 1, kInTree = 2, kLoose = 4;
  static void check(std::uint32_t id, const Aabb& box);
  std::vector<Aabb> boxes_;            // by id
  std::vector<std::uint8_t> flags_;    // by id: kLive, kInTree (the tree's entry is current), kLoose (in loose_)
  std::vector<std::uint32_t> loose_;   // ids set since the build (some may be erased since)
  std::vector<std::uint32_t> ids_;     // scratch: the live ids a build takes
  std::size_t live_ = 0;
  bool stale_ = false;                 // the next query rebuilds the tree
  std::uint64_t builds_ = 0;
  BoxTree tree_;
};

}  // namespace bpaccel
