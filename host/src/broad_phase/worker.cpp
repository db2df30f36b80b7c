#include "worker.hpp"

#include <algorithm>

#include "../core/keys.hpp"

namespace bpaccel {

Worker::Worker(const MakeHandOver& makeHandOver, std::size_t cellsPerBatch, std::size_t firstBatchCells, bool timed)
    : cellsPerBatch_(cellsPerBatch),
      timer_(timed),
      handOver_(makeHandOver(decoder_, timer_)),
      builder_(cellsPerBatch, firstBatchCells, handOver_->backend().keyWidth) {
  decoder_.setDeviceKeyWidth(handOver_->backend().keyWidth);
}

void Worker::startFrame(HandOverTimer::Clock::time_point start) {
  handOver_->startFrame();  // first: a failed frame's decoding may still write the pairs
  builder_.startFrame();
  decoder_.startFrame();
  timer_.startFrame(start);
}

void Worker::processCell(std::span<const KeyBox> keys, const DeviceCell& cell) {
  const std::size_t n = cell.items.size();
  if (n < 2) return;
  const BackendTraits& backend = handOver_->backend();
  if (n <= backend.capacity) {
    submit(keys, cell);
    return;
  }
  planChunks(n, backend.capacity, backend.bipartite, plan_);
  const auto chunk = [&](std::size_t p) {
    return cell.items.subspan(p * plan_.chunkSize, std::min(plan_.chunkSize, n - p * plan_.chunkSize));
  };
  for (const ChunkRun& run : plan_.runs) {
    // A chunk's items stay the cell's; a chunk pair's are copied. Neither
    // lasts: the region decides which pairs are owned.
    DeviceCell part;
    part.region = cell.region;
    part.keep = run.keep;
    if (run.alone()) {
      part.items = chunk(run.first);
      part.splitAt = part.items.size();
    } else {
      const auto first = chunk(run.first), second = chunk(run.second);
      pairItems_.assign(first.begin(), first.end());
      pairItems_.insert(pairItems_.end(), second.begin(), second.end());
      part.items = pairItems_;
      part.splitAt = first.size();
      part.deviceSplit = run.bipartite ? first.size() : 0;
    }
    submit(keys, part);
  }
}

void Worker::submit(std::span<const KeyBox> keys, const DeviceCell& cell) {
  if (cellsPerBatch_ <= 1) {
    runAlone(keys, cell);
    return;
  }
  if (builder_.add(cell, keys)) flush();
}

void Worker::runAlone(std::span<const KeyBox> keys, const DeviceCell& cell) {
  std::span<const KeyBox> packed = cell.packed;
  if (packed.empty()) {
    gathered_.resize(cell.items.size());
    for (std::size_t t = 0; t < cell.items.size(); ++t) gathered_[t] = keys[cell.items[t]];
    packed = gathered_;
  }
  std::span<const KeyBox> toDevice = packed;
  if (const unsigned width = handOver_->backend().keyWidth; width < 32) {
    narrowed_.resize(packed.size());
    narrowKeys(packed, width, narrowed_);
    toDevice = narrowed_;
  }
  const PairFilter filter{cell.items, packed, cell.below, cell.region, cell.splitAt, cell.keep};
  handOver_->runCell(filter, toDevice, cell.deviceSplit);
}

void Worker::flush() {
  if (builder_.empty()) return;
  const auto toDevice = builder_.seal();
  handOver_->handOverBatch(builder_.batch(), toDevice);
}

void Worker::finish() {
  flush();
  handOver_->finish();
}

}  // namespace bpaccel
