#include "cell_planner.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "device_cell.hpp"

namespace bpaccel {

void planChunks(std::size_t n, std::size_t capacity, bool bipartite, ChunkPlan& plan) {
  if (capacity < 2 || n <= capacity)
    throw std::invalid_argument(fmt::format("cell planner: {} boxes need no chunks on a capacity of {}", n, capacity));
  plan.chunkSize = capacity / 2;
  plan.chunks = (n + plan.chunkSize - 1) / plan.chunkSize;
  plan.runs.clear();
  const std::size_t k = plan.chunks;
  const auto size = [&](std::size_t p) { return std::min(plan.chunkSize, n - p * plan.chunkSize); };
  if (bipartite)
    for (std::size_t p = 0; p < k; ++p)
      if (size(p) >= 2) plan.runs.push_back({p, p, kFirstInside, false});
  for (std::size_t p = 0; p < k; ++p)
    for (std::size_t q = p + 1; q < k; ++q) {
      int keep = kCross;
      if (!bipartite && q == p + 1) keep |= kFirstInside;
      if (!bipartite && p == k - 2 && q == k - 1) keep |= kSecondInside;
      plan.runs.push_back({p, q, keep, bipartite});
    }
}

}  // namespace bpaccel
