#pragma once
// What one thread of a BroadPhase does with the cells it is given: cover each
// with device cells, fill batches, hand them over, decode the answers.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "answer_decoder.hpp"
#include "batch.hpp"
#include "cell_planner.hpp"
#include "device_cell.hpp"
#include "hand_over.hpp"
#include "timing.hpp"

namespace bpaccel {

class Worker {
 public:
  /// Makes the worker's hand-over, which decodes into and times with the worker's own.
  using MakeHandOver = std::function<std::unique_ptr<HandOver>(AnswerDecoder&, HandOverTimer&)>;
  /// `timed`: the hand-overs are timed (an observer wants the frame's timing).
  Worker(const MakeHandOver& makeHandOver, std::size_t cellsPerBatch, std::size_t firstBatchCells, bool timed);
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  const BackendTraits& backend() const { return handOver_->backend(); }
  /// Clears the last frame's results (after settling what a failed frame left).
  void startFrame(HandOverTimer::Clock::time_point start);
  /// A partition cell, or the whole scene: one device cell within the
  /// capacity, else its chunks (planChunks). `keys`: the frame's keys.
  void processCell(std::span<const KeyBox> keys, const DeviceCell& cell);
  /// Hands the last, partly filled batch over and waits for every answer.
  void finish();
  void awaken() { handOver_->awaken(); }

  std::vector<Pair>& pairs() { return decoder_.pairs(); }
  const RunStats& stats() const { return decoder_.stats(); }
  const HandOverTimer& timer() const { return timer_; }

 private:
  void submit(std::span<const KeyBox> keys, const DeviceCell& cell);
  void runAlone(std::span<const KeyBox> keys, const DeviceCell& cell);  // one cell, one run
  void flush();  // hands the batch being filled over, if any

  std::size_t cellsPerBatch_;
  AnswerDecoder decoder_;
  HandOverTimer timer_;
  std::vector<KeyBox> gathered_;        // runAlone's cell, packed
  std::vector<KeyBox> narrowed_;        // runAlone's cell, narrowed for the device
  std::vector<std::uint32_t> pairItems_;  // a chunk pair's items
  ChunkPlan plan_;
  // Last, so it goes first: its threads stop (after their last hand-over)
  // before the decoder and the timer they write.
  std::unique_ptr<HandOver> handOver_;
  BatchBuilder builder_;
};

}  // namespace bpaccel
