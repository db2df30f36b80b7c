#pragma once
// One cell as the device runs it: a partition cell, or a chunk or chunk pair
// of a cell above the device's capacity, with what its decoding keeps.

#include <cstddef>
#include <cstdint>
#include <span>

#include "../core/types.hpp"
#include "../partition/partition.hpp"

namespace bpaccel {

/// Which pairs of a device cell are kept (bits): the pairs across its two
/// chunks, and the inside pairs of its first or of its second chunk.
enum KeepPairs : int { kCross = 1, kFirstInside = 2, kSecondInside = 4 };

struct DeviceCell {
  std::span<const std::uint32_t> items;  // the boxes' indices in the scene, in the device's order
  /// The boxes in item order where the caller has them (tree leaves, grid
  /// cells, the whole scene); empty: gathered from the frame's keys.
  std::span<const KeyBox> packed;
  /// The partition's below() bits of the items (only where `lasting`); empty: the region decides.
  std::span<const std::uint8_t> below;
  /// The partition cell's region: a pair is kept only where its reference
  /// point lies in it. Null: the whole scene, every pair its own.
  const Cell* region = nullptr;
  std::size_t splitAt = 0;  // items before it form the first chunk (all of them for a whole cell)
  int keep = kFirstInside;
  std::size_t deviceSplit = 0;  // non-zero: the device runs it bipartite (cross pairs only)
  /// Items, packed and below stay valid until the batch is handed over, so a
  /// batch may refer to them; otherwise they are valid during the call only.
  bool lasting = false;

  /// A whole partition cell (or the scene): one run, all its pairs owned where its region says.
  static DeviceCell whole(std::span<const std::uint32_t> items, std::span<const KeyBox> packed,
                          std::span<const std::uint8_t> below, const Cell* region, bool lasting) {
    return {items, packed, lasting ? below : std::span<const std::uint8_t>{}, region, items.size(), kFirstInside, 0,
            lasting};
  }
};

}  // namespace bpaccel
