#pragma once
// A device emulated for its modelled time: to measure the host's threads as
// they would drive a real device, on a machine that has none.

#include <chrono>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "device/async_backend.hpp"
#include "device/backend.hpp"
#include "broad_phase/broad_phase.hpp"
#include "timeline.hpp"

namespace bpaccel {

/// Each hand-over's answer of one frame, in hand-over order.
using AnswerRecording = std::vector<BatchResult>;

/// A backend whose answers are recorded: the inner backend (rtl, model)
/// answers, and each hand-over's own answer is appended to `recording`
/// (which the caller clears between frames). Batches only.
class RecordingBackend final : public Backend {
 public:
  RecordingBackend(std::unique_ptr<Backend> inner, AnswerRecording& recording);
  std::string name() const override { return inner_->name(); }
  std::size_t capacity() const override { return inner_->capacity(); }
  unsigned keyWidth() const override { return inner_->keyWidth(); }
  bool bipartite() const override { return inner_->bipartite(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override;
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override;

 private:
  std::unique_ptr<Backend> inner_;
  AnswerRecording& recording_;
};

/// A device that takes its modelled time and no more: it answers each
/// hand-over with the answer recorded for it (so emulating the device costs
/// its thread nothing: the model backend's own all-pairs work would take
/// longer than the device it models) once a command's latency, the load, the
/// run (or the results on the link, if longer) and a completion's latency
/// have passed since the hand-over reached it (handOverTimes, the model's own
/// parts). It holds the device through both latencies, which the model
/// overlaps with the hand-overs before and after: up to 2 latencies a
/// hand-over more than the model. Run it on a thread of its own
/// (BroadPhase with HandOvers::Asynchronous or Polled); each frame, rewind()
/// it before the broad phase runs the frame whose answers are recorded.
class PacedBackend final : public Backend {
 public:
  using Clock = std::chrono::steady_clock;
  /// `recorded`: the device whose answers `recording` holds (its capacity,
  /// key width and runs are this one's). `model`: the clock and link.
  PacedBackend(const AnswerRecording& recording, const Backend& recorded, const PipelineModel& model);
  std::string name() const override { return "paced replay of " + recorded_.name(); }
  std::size_t capacity() const override { return recorded_.capacity(); }
  unsigned keyWidth() const override { return recorded_.keyWidth(); }
  bool bipartite() const override { return recorded_.bipartite(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override;
  /// Throws std::logic_error if the hand-over is not the recorded one (more
  /// hand-overs, or another cell count, than recorded).
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override;

  /// Called before each frame: its hand-overs replay the recording from the start.
  void rewind(Clock::time_point frameStart);
  /// Read once a frame has ended. Per hand-over of each frame so far: when
  /// it reached the device and when the device answered (s from the frame's
  /// start).
  const std::vector<std::vector<std::pair<double, double>>>& spans() const { return spans_; }
  /// How late the device answered each hand-over, s, all frames together.
  const std::vector<double>& lateSeconds() const { return lateSeconds_; }

 private:
  // A sleep ends about 15-20 us late here: sleep to this much before the end, then spin.
  static constexpr std::chrono::microseconds kSpin{30};
  const AnswerRecording& recording_;
  const Backend& recorded_;
  PipelineModel model_;
  std::size_t next_ = 0;
  Clock::time_point frameStart_;
  std::vector<std::vector<std::pair<double, double>>> spans_;
  std::vector<double> lateSeconds_;
};

/// A broad phase whose batches go, with the asynchronous hand-overs of
/// `config` (Asynchronous or Polled), to a PacedBackend that replays
/// `recording`: each frame it runs the boxes of the frame whose answers were
/// last recorded, on the host's threads as they would drive a real device,
/// with the device's durations emulated. `recorded` is the device that
/// recorded them; the partition, cell size and batches must be the recording run's.
class PacedBroadPhase {
 public:
  PacedBroadPhase(const AnswerRecording& recording, const Backend& recorded, const PipelineModel& model,
                  const BroadPhaseConfig& config);
  /// Untimed, before a frame: the emulated device awake, as a card needs no
  /// waking (BroadPhase::awakenDevices).
  void awakenDevice() { phase_->awakenDevices(); }
  /// The recorded frame again: the device replays the recording from its start.
  void findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);
  const BroadPhase& phase() const { return *phase_; }
  const PacedBackend& device() const { return *device_; }

 private:
  PacedBackend* device_ = nullptr;  // owned by phase_'s device thread
  std::unique_ptr<BroadPhase> phase_;
};

}  // namespace bpaccel
