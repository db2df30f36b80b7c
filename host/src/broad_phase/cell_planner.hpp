#pragma once
// How a cell above the device's capacity is covered: pure arithmetic on its
// size, so every pair is kept exactly once (tests prove it over many sizes).

#include <cstddef>
#include <vector>

namespace bpaccel {

/// One device run of a cell cut into chunks of `ChunkPlan::chunkSize` boxes:
/// chunk `first` alone (second == first), or chunks first < second together.
struct ChunkRun {
  std::size_t first = 0, second = 0;
  int keep = 0;            // KeepPairs bits: which of the run's pairs its decoding keeps
  bool bipartite = false;  // the device tests only the pairs across the two chunks
  bool alone() const { return first == second; }
};

struct ChunkPlan {
  std::size_t chunkSize = 0;  // boxes of every chunk but the last (capacity / 2)
  std::size_t chunks = 0;
  std::vector<ChunkRun> runs;  // in the order the device gets them
};

/// The runs that cover a cell of `n` boxes, n above `capacity` (at least 2):
/// k chunks of capacity/2 boxes. With bipartite runs each chunk of two boxes
/// or more runs alone for its inside pairs, then every two chunks p < q run as
/// one bipartite run for their cross pairs: each pair is tested once.
/// Otherwise every two chunks p < q run together and keep their cross pairs,
/// and each chunk's inside pairs are kept from exactly one run: chunk p's from
/// run (p, p+1), the last chunk's from run (k-2, k-1); those pairs are tested
/// again in every run their chunk is in. `plan` is reused (its storage kept).
void planChunks(std::size_t n, std::size_t capacity, bool bipartite, ChunkPlan& plan);

}  // namespace bpaccel
