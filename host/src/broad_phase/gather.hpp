#pragma once
// Reading boxes through a list of their indices: in a large scene they lie
// scattered, so each read is asked for some items ahead and the misses overlap
// (at 1,000,000 boxes each read would otherwise wait for memory).

#include <cstddef>
#include <cstdint>
#include <span>

#include "../core/types.hpp"

namespace bpaccel {

/// How many items ahead a gather asks for its box.
inline constexpr std::size_t kGatherAhead = 16;

/// Asks for boxes[ids[k + kGatherAhead]], where ids has that item.
inline void prefetchAhead(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids, std::size_t k) {
  if (k + kGatherAhead < ids.size()) __builtin_prefetch(&boxes[ids[k + kGatherAhead]]);
}

}  // namespace bpaccel
