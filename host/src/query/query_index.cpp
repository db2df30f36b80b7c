#include "query_index.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

void QueryIndex::check(std::uint32_t id, const Aabb& box) {
  static constexpr char kAxis[3] = {'x', 'y', 'z'};
  for (int a = 0; a < 3; ++a) {
    if (std::isnan(box.min[a]) || std::isnan(box.max[a]))
      throw std::invalid_argument(fmt::format("query index: box {} has NaN on {} (min {}, max {})", id, kAxis[a],
                                              box.min[a], box.max[a]));
    if (box.min[a] > box.max[a])
      throw std::invalid_argument(
          fmt::format("query index: box {} has min {} > max {} on {}", id, box.min[a], box.max[a], kAxis[a]));
  }
}

void QueryIndex::assign(std::span<const Aabb> boxes) {
  for (std::size_t i = 0; i < boxes.size(); ++i) check(static_cast<std::uint32_t>(i), boxes[i]);
  boxes_.assign(boxes.begin(), boxes.end());
  flags_.assign(boxes.size(), kLive);
  loose_.clear();
  live_ = boxes.size();
  stale_ = true;
}

void QueryIndex::set(std::uint32_t id, const Aabb& box) {
  check(id, box);
  if (id >= boxes_.size()) {
    boxes_.resize(std::size_t{id} + 1);
    flags_.resize(std::size_t{id} + 1, 0);
  }
  boxes_[id] = box;
  std::uint8_t& f = flags_[id];
  if (!(f & kLive)) ++live_;
  f = static_cast<std::uint8_t>((f | kLive) & ~kInTree);
  if (stale_ || (f & kLoose)) return;
  f |= kLoose;
  loose_.push_back(id);
  if (loose_.size() > 64 + live_ / 64) stale_ = true;
}

void QueryIndex::erase(std::uint32_t id) {
  if (!contains(id)) throw std::invalid_argument(fmt::format("query index: erase: no box {}", id));
  flags_[id] = static_cast<std::uint8_t>(flags_[id] & kLoose);
  --live_;
}

void QueryIndex::clear() {
  boxes_.clear();
  flags_.clear();
  loose_.clear();
  live_ = 0;
  stale_ = true;
}

void QueryIndex::prepare() {
  if (!stale_) return;
  ids_.clear();
  for (std::size_t id = 0; id < flags_.size(); ++id) {
    flags_[id] = flags_[id] & kLive ? kLive | kInTree : 0;
    if (flags_[id]) ids_.push_back(static_cast<std::uint32_t>(id));
  }
  tree_.build(boxes_, ids_);
  loose_.clear();
  stale_ = false;
  ++builds_;
}

void QueryIndex::rayTest(RayQuery& ray, const QueryHit& hit) {
  prepare();
  tree_.rayTest(ray, [&](std::uint32_t id) {
    if (flags_[id] & kInTree) hit(id);
  });
  for (const std::uint32_t id : loose_)
    if ((flags_[id] & kLive) && rayMeetsBox(ray, boxes_[id], ray.lambdaMax)) hit(id);
}

void QueryIndex::aabbTest(const Aabb& box, const QueryHit& hit) {
  prepare();
  tree_.aabbTest(box, [&](std::uint32_t id) {
    if (flags_[id] & kInTree) hit(id);
  });
  for (const std::uint32_t id : loose_)
    if ((flags_[id] & kLive) && boxesOverlap(boxes_[id], box)) hit(id);
}

}  // namespace bpaccel
