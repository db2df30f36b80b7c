#include "many_worlds.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "../core/keys.hpp"

namespace bpaccel {

ManyWorlds::ManyWorlds(Backend& backend, const BroadPhaseConfig& config) : backend_(backend), large_(backend, config) {}

void ManyWorlds::findPairs(std::span<const std::span<const Aabb>> worlds, WorldPairs& out) {
  out.pairs_.clear();
  out.ends_.clear();
  stats_ = {};
  convert(worlds);
  runSmallWorlds();
  collect(worlds.size(), worlds, out);
}

// Every world's keys, checked world by world so that an error names its world.
void ManyWorlds::convert(std::span<const std::span<const Aabb>> worlds) {
  keys_.clear();
  starts_.assign(1, 0);
  smallWorlds_.clear();
  std::vector<KeyBox> worldKeys;
  for (std::size_t w = 0; w < worlds.size(); ++w) {
    try {
      toKeys(worlds[w], worldKeys);
    } catch (const InputError& e) {
      throw std::invalid_argument(fmt::format("world {}: {}", w, e.what()));
    }
    keys_.insert(keys_.end(), worldKeys.begin(), worldKeys.end());
    starts_.push_back(keys_.size());
    if (worldKeys.size() >= 2 && worldKeys.size() <= backend_.capacity()) smallWorlds_.push_back(w);
  }
}

// The worlds that fit a run, one cell each, in one runBatch (the backend
// batches them as its device does); keys narrowed where the device compares fewer bits.
void ManyWorlds::runSmallWorlds() {
  const unsigned width = backend_.keyWidth();
  if (width < 32) narrowed_.resize(keys_.size());
  cells_.clear();
  for (const std::size_t w : smallWorlds_) {
    const std::span<const KeyBox> world(keys_.data() + starts_[w], starts_[w + 1] - starts_[w]);
    if (width < 32) {
      const std::span<KeyBox> into(narrowed_.data() + starts_[w], world.size());
      narrowKeys(world, width, into);
      cells_.emplace_back(into);
    } else {
      cells_.push_back(world);
    }
  }
  cellPairs_.clear();
  cellEnds_.clear();
  if (!cells_.empty()) backend_.runBatch(cells_, cellPairs_, cellEnds_, stats_);
}

// Each world's pairs in world order: a batched world's checked with the full
// keys where they were narrowed, a large world's from the BroadPhase.
void ManyWorlds::collect(std::size_t worlds, std::span<const std::span<const Aabb>> boxes, WorldPairs& out) {
  const bool narrowed = backend_.keyWidth() < 32;
  std::size_t cell = 0;
  for (std::size_t w = 0; w < worlds; ++w) {
    const std::size_t n = starts_[w + 1] - starts_[w], from = out.pairs_.size();
    if (cell < smallWorlds_.size() && smallWorlds_[cell] == w) {
      const KeyBox* keys = keys_.data() + starts_[w];
      for (std::size_t k = cell == 0 ? 0 : cellEnds_[cell - 1]; k < cellEnds_[cell]; ++k) {
        const auto [i, j] = cellPairs_[k];
        if (!narrowed || overlapsBranchFree(keys[i], keys[j])) out.pairs_.push_back({std::min(i, j), std::max(i, j)});
      }
      ++cell;
    } else if (n >= 2) {
      large_.findPairs(boxes[w], largePairs_);
      out.pairs_.insert(out.pairs_.end(), largePairs_.begin(), largePairs_.end());
    }
    std::sort(out.pairs_.begin() + static_cast<std::ptrdiff_t>(from), out.pairs_.end());
    out.ends_.push_back(out.pairs_.size());
  }
}

}  // namespace bpaccel
