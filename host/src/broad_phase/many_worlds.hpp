#pragma once
// ManyWorlds: the pairs of many independent small worlds in one call, each
// world a device cell and the worlds handed over together (batched learning
// and simulation step thousands of worlds of tens of bodies each).

#include <cstddef>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "../device/backend.hpp"
#include "broad_phase.hpp"

namespace bpaccel {

/// Every world's pairs in one array: world w's are pairs()[begin(w) .. end(w)).
class WorldPairs {
 public:
  std::size_t worlds() const { return ends_.size(); }
  std::size_t begin(std::size_t w) const { return w == 0 ? 0 : ends_[w - 1]; }
  std::size_t end(std::size_t w) const { return ends_[w]; }
  /// World w's pairs: indices into that world's boxes, i < j, sorted.
  std::span<const Pair> of(std::size_t w) const {
    return std::span<const Pair>(pairs_).subspan(begin(w), end(w) - begin(w));
  }
  const std::vector<Pair>& pairs() const { return pairs_; }

 private:
  friend class ManyWorlds;
  std::vector<Pair> pairs_;
  std::vector<std::size_t> ends_;
};

class ManyWorlds {
 public:
  /// On `backend` (which must outlive it). A world with more boxes than the
  /// backend's capacity goes through a BroadPhase of `config` on the same backend.
  explicit ManyWorlds(Backend& backend, const BroadPhaseConfig& config = {});

  /// Each world's overlapping pairs (inclusive, as everywhere in the library)
  /// into `out`. A bad box (NaN, min above max) throws std::invalid_argument
  /// naming the world and the box; `out` is then empty.
  void findPairs(std::span<const std::span<const Aabb>> worlds, WorldPairs& out);
  /// The last call's device counters (the batched worlds' only).
  const RunStats& stats() const { return stats_; }

 private:
  void convert(std::span<const std::span<const Aabb>> worlds);
  void runSmallWorlds();
  void collect(std::size_t worlds, std::span<const std::span<const Aabb>> boxes, WorldPairs& out);

  Backend& backend_;
  BroadPhase large_;
  RunStats stats_;
  std::vector<KeyBox> keys_, narrowed_;         // every world's keys, one after another
  std::vector<std::size_t> starts_;             // world w's keys from starts_[w] to starts_[w + 1]
  std::vector<std::size_t> smallWorlds_;        // the worlds run as cells, in cell order
  std::vector<std::span<const KeyBox>> cells_;
  std::vector<Pair> cellPairs_, largePairs_;
  std::vector<std::size_t> cellEnds_;
};

}  // namespace bpaccel
