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

void Backend::runBipartite(std::span<const KeyBox>, std::size_t, std::vector<Pair>&, RunStats&) {
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

ModelBackend::ModelBackend(std::size_t m, std::size_t capacity, std::uint64_t runOverheadCycles,
                           std::uint64_t streamReadLatency, std::size_t batchCells, bool overlapsLoads,
                           unsigned keyWidth)
    : m_(m),
      capacity_(capacity),
      overhead_(runOverheadCycles),
      streamReadLatency_(streamReadLatency),
      batchCells_(batchCells),
      overlapsLoads_(overlapsLoads),
      keyWidth_(keyWidth) {
  if (keyWidth < 1 || keyWidth > 32)
    throw std::invalid_argument(fmt::format("model: key width {} outside 1 .. 32", keyWidth));
  // Only the seed architecture stripes objects over m memories.
  if (m == 0 || capacity < 2 || (streamReadLatency == 0 && capacity % m != 0))
    throw std::invalid_argument(fmt::format("model: invalid m = {} / capacity = {}", m, capacity));
  if (batchCells == 0) throw std::invalid_argument("model: a batch must hold at least one cell");
}

void ModelBackend::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) {
  runAlone(boxes, 0, out, stats);
}

void ModelBackend::runBipartite(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                                RunStats& stats) {
  checkBipartite(boxes.size(), split);
  runAlone(boxes, split, out, stats);
}

void ModelBackend::runAlone(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                            RunStats& stats) const {
  runCell(boxes, split, out, stats);
  stats.loadCycles += boxes.size() + 1;  // one box a cycle, then the start cycle
  stats.cycles += busyCycles(boxes.size(), split);
  stats.runs += 1;
  stats.batches += 1;
}

void ModelBackend::runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                            std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  for (const auto& cell : cells)
    if (cell.size() > capacity_)
      throw std::length_error(fmt::format("model: a cell of {} boxes exceeds the capacity {}", cell.size(), capacity_));
  checkSplits(cells, splits);
  for (std::size_t first = 0; first < cells.size(); first += batchCells_) {
    const std::size_t count = std::min(batchCells_, cells.size() - first);
    const auto batch = cells.subspan(first, count);
    const auto batchSplits = splitsOf(splits, first, count);
    for (std::size_t k = 0; k < count; ++k) {
      runCell(batch[k], splitOf(batchSplits, k), out, stats);
      cellEnds.push_back(out.size());
    }
    // The cycles come from the batch's timeline, not from its cells one by one.
    batchCycles(batch, batchSplits, stats);
    stats.runs += count;
    stats.batches += 1;
  }
}

void ModelBackend::runCell(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                           RunStats& stats) const {
  const std::size_t n = boxes.size();
  if (n > capacity_) throw std::length_error(fmt::format("model: {} boxes exceed the capacity {}", n, capacity_));
  checkKeyWidth(boxes);
  const std::size_t before = out.size();
  // Block b, window start s: lane k tests (b*m + k, s + k) while s + k < n,
  // exactly as the hardware's sequencer issues it. A beat is one cycle with a hit.
  // A bipartite run (split = na) runs the A blocks, from s = max(base + 1,
  // na - 2m + 1) (where the stream's jump lands), its lanes k testing A
  // objects base + k < na against B objects s + k >= na.
  std::uint64_t beats = 0;
  const std::size_t lastA = split == 0 ? n - 2 : split - 1;
  for (std::size_t base = 0; n >= 2 && base <= lastA; base += m_) {
    const std::size_t first = split > 2 * m_ ? std::max(base + 1, split - 2 * m_ + 1) : base + 1;
    for (std::size_t s = first; s < n; ++s) {
      bool hit = false;
      // Lanes past the last B object, and (bipartite) past the last A object, test nothing.
      const std::size_t lanes = std::min({m_, n - s, (split == 0 ? n : split) - base});
      for (std::size_t k = s < split ? split - s : 0; k < lanes; ++k) {
        if (overlaps(boxes[base + k], boxes[s + k])) {
          out.emplace_back(static_cast<std::uint32_t>(base + k), static_cast<std::uint32_t>(s + k));
          hit = true;
        }
      }
      beats += hit;
    }
  }
  stats.issueCycles += scheduleIssueCycles(n, m_, split);
  stats.hits += out.size() - before;
  stats.boxesSent += n;
  stats.beatsReceived += beats;
}

std::uint64_t ModelBackend::startupCycles(std::uint64_t n) const {
  // Stream: the first reads reach the window's entry while the start's copy
  // of objects 0 .. m fills the window and the A block.
  if (n < 2) return 0;
  return streamReadLatency_;
}

std::uint64_t ModelBackend::busyCycles(std::uint64_t n, std::uint64_t split) const {
  return n < 2 ? 0 : startupCycles(n) + scheduleIssueCycles(n, m_, split) + overhead_;
}

void ModelBackend::batchCycles(std::span<const std::span<const KeyBox>> batch, std::span<const std::size_t> splits,
                               RunStats& stats) const {
  // Cycle 0 takes the first count; every count and box is offered as soon as
  // the device can take it, and the consumer never stalls.
  std::uint64_t countTaken = 0;   // the cycle the device takes the cell's count
  std::uint64_t nextStart = 0;    // earliest start: the cycle after the last cell ended
  std::uint64_t end = 0, run = 0;
  for (std::size_t k = 0; k < batch.size(); ++k) {
    const std::uint64_t n = batch[k].size();
    const std::uint64_t lastBox = countTaken + n;  // one box a cycle after the count
    const std::uint64_t start = std::max(lastBox + 1, nextStart);
    const bool launched = n >= 2 && n <= capacity_;
    const std::uint64_t busy = launched ? busyCycles(n, splitOf(splits, k)) : 0;
    end = start + busy + 1;  // the front end's own cycle ends the cell
    run += busy + 1;
    nextStart = end + 1;
    // The next count: at this start where loads overlap runs, else when this cell ends.
    countTaken = overlapsLoads_ ? start : end;
  }
  stats.cycles += run;
  stats.loadCycles += end + 1 - run;
}

void CpuBackend::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) {
  const std::size_t before = out.size();
  kernel_.run(boxes, out, scratch_);
  stats.runs += 1;
  stats.batches += 1;
  stats.hits += out.size() - before;
}

}  // namespace bpaccel
