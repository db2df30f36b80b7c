#include "model_backend.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

ModelBackend::ModelBackend(const DeviceParams& params) : params_(params) { params_.check(); }

void ModelBackend::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) {
  runSplit(boxes, 0, out, stats);
}

void ModelBackend::runSplit(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                            RunStats& stats) {
  // The device behind its shell starts a cell only as a batch: one run is a batch of one cell.
  runCell(boxes, split, out, stats);
  const std::span<const KeyBox> cell[] = {boxes};
  const std::size_t splits[] = {split};
  batchCycles(cell, splits, stats);
  stats.runs += 1;
  stats.batches += 1;
}

void ModelBackend::runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                            std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  for (const auto& cell : cells)
    if (cell.size() > params_.capacity)
      throw std::length_error(
          fmt::format("model: a cell of {} boxes exceeds the capacity {}", cell.size(), params_.capacity));
  checkSplits(cells, splits);
  for (std::size_t first = 0; first < cells.size(); first += params_.batchCells) {
    const std::size_t count = std::min(params_.batchCells, cells.size() - first);
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
  if (n > params_.capacity)
    throw std::length_error(fmt::format("model: {} boxes exceed the capacity {}", n, params_.capacity));
  checkKeyWidth(boxes);
  const std::size_t before = out.size();
  // Block b, window start s: lane k tests (b*m + k, s + k) while s + k < n,
  // exactly as the hardware's sequencer issues it. A beat is one cycle with a hit.
  // A bipartite run (split = na) runs the A blocks, from s = max(base + 1,
  // na - 2m + 1) (where the stream's jump lands), its lanes k testing A
  // objects base + k < na against B objects s + k >= na.
  std::uint64_t beats = 0;
  const std::size_t lastA = split == 0 ? n - 2 : split - 1;
  for (std::size_t base = 0; n >= 2 && base <= lastA; base += params_.lanes) {
    const std::size_t first = split > 2 * params_.lanes ? std::max(base + 1, split - 2 * params_.lanes + 1) : base + 1;
    for (std::size_t s = first; s < n; ++s) {
      bool hit = false;
      // Lanes past the last B object, and (bipartite) past the last A object, test nothing.
      const std::size_t lanes = std::min({params_.lanes, n - s, (split == 0 ? n : split) - base});
      for (std::size_t k = s < split ? split - s : 0; k < lanes; ++k) {
        if (overlaps(boxes[base + k], boxes[s + k])) {
          out.emplace_back(static_cast<std::uint32_t>(base + k), static_cast<std::uint32_t>(s + k));
          hit = true;
        }
      }
      beats += hit;
    }
  }
  stats.issueCycles += scheduleIssueCycles(n, params_.lanes, split);
  stats.hits += out.size() - before;
  stats.boxesSent += n;
  stats.beatsReceived += beats;
}

std::uint64_t ModelBackend::busyCycles(std::uint64_t n, std::uint64_t split) const {
  // Stream: the first reads reach the window's entry while the start's copy of
  // objects 0 .. m fills the window and the A block.
  return n < 2 ? 0 : params_.startupCycles() + scheduleIssueCycles(n, params_.lanes, split) + params_.runOverheadCycles;
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
    const bool launched = n >= 2 && n <= params_.capacity;
    const std::uint64_t busy = launched ? busyCycles(n, splitOf(splits, k)) : 0;
    end = start + busy + 1;  // the front end's own cycle ends the cell
    run += busy + 1;
    nextStart = end + 1;
    // The next count: at this start where loads overlap runs, else when this cell ends.
    countTaken = params_.batchOverlapsLoads ? start : end;
  }
  stats.cycles += run;
  stats.loadCycles += end + 1 - run;
}

}  // namespace bpaccel
