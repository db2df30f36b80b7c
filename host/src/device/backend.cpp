#include "backend.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

std::uint64_t scheduleIssueCycles(std::uint64_t n, std::uint64_t m, std::uint64_t split) {
  if (n < 2) return 0;
  if (split >= n) throw std::invalid_argument(fmt::format("schedule: split {} is not below n = {}", split, n));
  const std::uint64_t lastA = split == 0 ? n - 2 : split - 1;
  const std::uint64_t blocks = lastA / m + 1;
  // Blocks with b*m < na - 2m jump past their prefix: 2m - 1 + nb cycles each.
  const std::uint64_t full = split > 2 * m ? std::min(blocks, (split - 2 * m + m - 1) / m) : 0;
  const std::uint64_t fullCycles = full * (2 * m - 1 + (n - split));
  // The others take n - 1 - b*m: b = full .. blocks-1.
  return fullCycles + (blocks - full) * (n - 1) - m * (blocks * (blocks - 1) / 2 - full * (full - 1) / 2);
}

void Backend::runBipartite(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                           RunStats& stats) {
  checkBipartite(boxes.size(), split);
  runSplit(boxes, split, out, stats);
}

void Backend::runSplit(std::span<const KeyBox>, std::size_t, std::vector<Pair>&, RunStats&) {
  throw std::logic_error(fmt::format("{}: no bipartite runs on this backend", name()));
}

void Backend::checkBipartite(std::size_t n, std::size_t split) const {
  if (!bipartite()) throw std::logic_error(fmt::format("{}: no bipartite runs on this backend", name()));
  if (split < 1 || split >= n)
    throw std::invalid_argument(fmt::format("{}: bipartite split {} outside 1 .. n-1 (n = {})", name(), split, n));
}

void Backend::checkKeyWidth(std::span<const KeyBox> boxes) const {
  const unsigned width = keyWidth();
  if (width >= 32) return;
  std::uint32_t any = 0;  // the OR of every key: one branch for the whole cell
  for (const KeyBox& b : boxes)
    for (int a = 0; a < 3; ++a) any |= b.min[a] | b.max[a];
  if ((any >> width) == 0) return;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a)
      if (((boxes[i].min[a] | boxes[i].max[a]) >> width) != 0)
        throw std::invalid_argument(
            fmt::format("{}: box {} has a key wider than the device's {} bits on axis {} (min {:#x}, max {:#x}); "
                        "narrow the keys first (narrowKeys)",
                        name(), i, width, a, boxes[i].min[a], boxes[i].max[a]));
}

void Backend::checkSplits(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits) const {
  if (splits.empty()) return;
  if (splits.size() != cells.size())
    throw std::invalid_argument(
        fmt::format("{}: {} splits for a batch of {} cells (give one per cell, or none)", name(), splits.size(),
                    cells.size()));
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (splits[k] == 0) continue;
    try {
      checkBipartite(cells[k].size(), splits[k]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("{} (cell {} of the batch)", e.what(), k));
    }
  }
}

void Backend::runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                       std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  checkSplits(cells, splits);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const std::size_t split = splitOf(splits, k);
    if (split == 0)
      run(cells[k], out, stats);
    else
      runBipartite(cells[k], split, out, stats);
    cellEnds.push_back(out.size());
  }
}

}  // namespace bpaccel
