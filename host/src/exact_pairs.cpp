#include "exact_pairs.hpp"

#include <algorithm>
#include <numeric>

namespace bpaccel {

void exactPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  out.clear();
  std::vector<std::uint32_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return boxes[a].min[0] < boxes[b].min[0]; });
  for (std::size_t s = 0; s < order.size(); ++s) {
    const Aabb& a = boxes[order[s]];
    // Later boxes start at or after a's min x; they overlap on x while they start by a's max x.
    for (std::size_t t = s + 1; t < order.size() && boxes[order[t]].min[0] <= a.max[0]; ++t) {
      const Aabb& b = boxes[order[t]];
      if (a.min[1] <= b.max[1] && b.min[1] <= a.max[1] && a.min[2] <= b.max[2] && b.min[2] <= a.max[2] &&
          b.min[0] <= a.max[0] && a.min[0] <= b.max[0])
        out.emplace_back(std::min(order[s], order[t]), std::max(order[s], order[t]));
    }
  }
  std::sort(out.begin(), out.end());
}

}  // namespace bpaccel
