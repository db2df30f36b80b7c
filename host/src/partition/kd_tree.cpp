#include "kd_tree.hpp"

#include <algorithm>

#include "../core/keys.hpp"

namespace bpaccel {

void KdTree::build(std::span<const KeyBox> boxes, std::size_t cellSize, const LeafSink& onLeaf, Layout layout) {
  checkObjectCount(boxes.size());
  leafItems_.clear();
  leaves_.clear();
  stack_.clear();
  const auto n = static_cast<std::uint32_t>(boxes.size());
  work_.resize(n);
  for (std::uint32_t i = 0; i < n; ++i) work_[i] = i;
  const bool carried = layout == Layout::Carried || (layout == Layout::Auto && boxes.size() > kCarryAbove);
  if (carried)
    workKeys_.assign(boxes.begin(), boxes.end());
  else
    workKeys_.clear();
  constexpr std::uint64_t kTop = std::uint64_t{1} << 32;
  stack_.push_back({0, n, {0, 0, 0}, {kTop, kTop, kTop}});
  while (!stack_.empty()) {
    const Task task = stack_.back();
    stack_.pop_back();
    if (task.count <= cellSize || !(carried ? split<true>(boxes, task) : split<false>(boxes, task))) {
      const auto items = work_.begin() + static_cast<std::ptrdiff_t>(task.begin);
      leaves_.push_back({leafItems_.size(), task.count, task.lo, task.hi});
      leafItems_.insert(leafItems_.end(), items, items + task.count);
      if (onLeaf) {
        std::span<const KeyBox> packed;
        if (carried) packed = std::span<const KeyBox>(workKeys_).subspan(static_cast<std::size_t>(task.begin), task.count);
        onLeaf(leaves_.back(), this->items(leaves_.back()), packed);
      }
      work_.resize(task.begin);  // the next node on the stack owns the end again
      if (carried) workKeys_.resize(task.begin);
    }
  }
}

// Chooses the plane from a fixed-size sample of box centres (a strided
// sample keeps the cost per node constant). Tries the axes from widest sampled
// spread down and splits at the sampled median. A split must shrink both
// children and may duplicate at most a quarter of the boxes, which bounds
// the tree's size. Each level costs one pass over its boxes.
template <bool kCarried>
bool KdTree::split(std::span<const KeyBox> boxes, const Task& task) {
  constexpr std::uint32_t kSamples = 63;
  const std::uint32_t samples = std::min(kSamples, task.count);
  std::array<std::array<std::uint64_t, kSamples>, 3> centres;  // twice the centre, per axis
  for (std::uint32_t t = 0; t < samples; ++t) {
    const std::uint64_t at = task.begin + std::uint64_t{t} * task.count / samples;
    const KeyBox& b = kCarried ? workKeys_[at] : boxes[work_[at]];
    for (int a = 0; a < 3; ++a) centres[a][t] = std::uint64_t{b.min[a]} + b.max[a];
  }
  std::array<std::uint64_t, 3> spread{}, lowest{};
  for (int a = 0; a < 3; ++a) {
    const auto [lo, hi] = std::minmax_element(centres[a].begin(), centres[a].begin() + samples);
    spread[a] = *hi - *lo;
    lowest[a] = *lo;
  }
  std::array<int, 3> axes{0, 1, 2};
  std::sort(axes.begin(), axes.end(), [&](int x, int y) { return spread[x] > spread[y]; });

  for (int axis : axes) {
    if (spread[axis] == 0) break;
    auto* c = centres[axis].data();
    std::nth_element(c, c + samples / 2, c + samples);
    const std::uint64_t median = c[samples / 2];
    // Plane in key space: ceil(median centre), strictly above the lowest sampled centre.
    std::uint64_t plane = std::max((median + 1) / 2, (lowest[axis] + 2) / 2);
    plane = std::max(plane, task.lo[axis] + 1);
    if (plane >= task.hi[axis]) continue;

    // One pass: each item goes to the lower child, the upper one or both.
    if (left_.size() < task.count) {  // grow only: shrinking and growing again would clear them at every node
      left_.resize(task.count);
      right_.resize(task.count);
    }
    if (kCarried && leftKeys_.size() < task.count) {
      leftKeys_.resize(task.count);
      rightKeys_.resize(task.count);
    }
    std::uint32_t left = 0, right = 0;
    for (std::uint32_t t = 0; t < task.count; ++t) {
      const std::uint32_t id = work_[task.begin + t];
      const KeyBox& b = kCarried ? workKeys_[task.begin + t] : boxes[id];
      left_[left] = id;
      right_[right] = id;
      if constexpr (kCarried) {
        leftKeys_[left] = b;
        rightKeys_[right] = b;
      }
      left += b.min[axis] < plane;
      right += b.max[axis] >= plane;
    }
    if (left >= task.count || right >= task.count ||
        std::uint64_t{left} + right > std::uint64_t{task.count} + task.count / 4)
      continue;
    // The children replace their parent at the end of the work stack, the
    // lower one last so that it, popped first, owns the end.
    work_.resize(task.begin);
    work_.insert(work_.end(), right_.begin(), right_.begin() + right);
    work_.insert(work_.end(), left_.begin(), left_.begin() + left);
    if constexpr (kCarried) {
      workKeys_.resize(task.begin);
      workKeys_.insert(workKeys_.end(), rightKeys_.begin(), rightKeys_.begin() + right);
      workKeys_.insert(workKeys_.end(), leftKeys_.begin(), leftKeys_.begin() + left);
    }
    Task lower = task, upper = task;
    upper.count = right;
    upper.lo[axis] = plane;
    lower.begin = task.begin + right;
    lower.count = left;
    lower.hi[axis] = plane;
    stack_.push_back(upper);
    stack_.push_back(lower);
    return true;
  }
  return false;
}

}  // namespace bpaccel
