#pragma once
// Which of a device cell's reported pairs the broad phase keeps: a pure
// function of the pairs and the cell.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "../core/types.hpp"
#include "../partition/partition.hpp"
#include "device_cell.hpp"

namespace bpaccel {

/// What decides a device cell's pairs.
struct PairFilter {
  std::span<const std::uint32_t> items;  // scene index of each of the cell's boxes
  std::span<const KeyBox> boxes;         // their full keys, in item order
  std::span<const std::uint8_t> below;   // the partition's below() bits, or empty
  const Cell* region = nullptr;          // null: every pair owned
  std::size_t splitAt = 0;
  int keep = kFirstInside;
};

/// Writes the kept pairs (scene indices, i < j) from `to` on, room for every
/// one of `pairs` (indices into the cell), and returns the end. A pair is kept
/// when its kind (cross, first or second chunk's inside) is one `keep` asks
/// for and its reference point lies in the region: for a whole cell with
/// below() bits, decided from two bytes instead of two boxes. kCheckOverlap:
/// the device compared narrowed keys, so a pair is kept only where the full
/// keys overlap too. Every pair is written and the cursor moves on only for a
/// kept one: no branch to mispredict (about a sixth of a grid cell's hits
/// belong to another cell, at random).
template <bool kCheckOverlap>
Pair* keepPairs(std::span<const Pair> pairs, const PairFilter& cell, Pair* to) {
  const std::uint32_t* const ids = cell.items.data();
  const KeyBox* const boxes = cell.boxes.data();
  if (!cell.below.empty() && cell.keep == kFirstInside && cell.splitAt == cell.items.size()) {
    // One run of the whole cell: every pair is an inside pair of the first chunk.
    const std::uint8_t* const bits = cell.below.data();
    for (const auto& [a, b] : pairs) {
      const std::uint32_t i = ids[a], j = ids[b];
      *to = {std::min(i, j), std::max(i, j)};
      if constexpr (kCheckOverlap)
        to += static_cast<int>(ownsPair(bits[a], bits[b])) & static_cast<int>(overlapsBranchFree(boxes[a], boxes[b]));
      else
        to += ownsPair(bits[a], bits[b]);
    }
    return to;
  }
  for (const auto& [a, b] : pairs) {
    const bool firstA = a < cell.splitAt, firstB = b < cell.splitAt;
    const int kind = firstA != firstB ? kCross : (firstA ? kFirstInside : kSecondInside);
    const bool owned = !cell.region || cell.region->contains(referencePoint(boxes[a], boxes[b]));
    const std::uint32_t i = ids[a], j = ids[b];
    *to = {std::min(i, j), std::max(i, j)};
    int kept = static_cast<int>((cell.keep & kind) != 0) & static_cast<int>(owned);
    if constexpr (kCheckOverlap) kept &= static_cast<int>(overlapsBranchFree(boxes[a], boxes[b]));
    to += kept;
  }
  return to;
}

/// keepPairs with the overlap check where `narrowed`.
inline Pair* keepPairs(std::span<const Pair> pairs, const PairFilter& cell, bool narrowed, Pair* to) {
  return narrowed ? keepPairs<true>(pairs, cell, to) : keepPairs<false>(pairs, cell, to);
}

}  // namespace bpaccel
