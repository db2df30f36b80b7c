#include "paced_backend.hpp"

#include <algorithm>
#include <stdexcept>
#include <thread>

#include <sys/prctl.h>

namespace bpaccel {
namespace {

// Appends one hand-over's own answer to what Backend::runBatch fills.
void append(const BatchResult& answer, std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  const std::size_t base = out.size();
  out.insert(out.end(), answer.pairs.begin(), answer.pairs.end());
  for (const std::size_t end : answer.cellEnds) cellEnds.push_back(base + end);
  stats += answer.stats;
}

double seconds(PacedBackend::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

RecordingBackend::RecordingBackend(std::unique_ptr<Backend> inner, AnswerRecording& recording)
    : inner_(std::move(inner)), recording_(recording) {
  if (!inner_) throw std::invalid_argument("recording device: no backend to record");
}

void RecordingBackend::run(std::span<const KeyBox>, std::vector<Pair>&, RunStats&) {
  throw std::logic_error("recording device: batches only (cells per batch of at least 2)");
}

void RecordingBackend::runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                               std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  BatchResult r;  // this hand-over's own: its cell ends count from 0
  inner_->runBatch(cells, splits, r.pairs, r.cellEnds, r.stats);
  append(r, out, cellEnds, stats);
  recording_.push_back(std::move(r));
}

PacedBackend::PacedBackend(const AnswerRecording& recording, const Backend& recorded, const PipelineModel& model)
    : recording_(recording), recorded_(recorded), model_(model) {
  checkLink(model.link, model.clockHz, "paced backend");
  prctl(PR_SET_TIMERSLACK, 1UL);  // this thread's sleeps end on time, not up to 50 us late
}

void PacedBackend::run(std::span<const KeyBox>, std::vector<Pair>&, RunStats&) {
  throw std::logic_error("paced device: batches only (cells per batch of at least 2)");
}

void PacedBackend::rewind(Clock::time_point frameStart) {
  next_ = 0;
  frameStart_ = frameStart;
}

void PacedBackend::runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t>,
                           std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  const auto reached = Clock::now();
  if (next_ >= recording_.size() || recording_[next_].cellEnds.size() != cells.size())
    throw std::logic_error("paced device: the hand-overs differ from the recorded ones");
  const BatchResult& r = recording_[next_++];
  append(r, out, cellEnds, stats);
  const auto t = handOverTimes(r.stats, model_);
  const double hold = 2 * model_.link.latencySeconds + t.loadSeconds + std::max(t.computeSeconds, t.resultsSeconds);
  const auto until = reached + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(hold));
  std::this_thread::sleep_until(until - kSpin);
  while (Clock::now() < until) {
  }
  const auto answered = Clock::now();
  lateSeconds_.push_back(seconds(answered - until));
  if (next_ == 1) spans_.emplace_back();
  spans_.back().emplace_back(seconds(reached - frameStart_), seconds(answered - frameStart_));
}

PacedBroadPhase::PacedBroadPhase(const AnswerRecording& recording, const Backend& recorded,
                                 const PipelineModel& model, const BroadPhaseConfig& config) {
  if (config.handOvers == HandOvers::Synchronous || config.threads != 1)
    throw std::invalid_argument("paced broad phase: one thread with asynchronous hand-overs");
  // Built on the device's thread while the constructor waits: the pointer is set when it returns.
  phase_ = std::make_unique<BroadPhase>(
      [&] {
        auto device = std::make_unique<PacedBackend>(recording, recorded, model);
        device_ = device.get();
        return device;
      },
      config);
}

void PacedBroadPhase::findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  device_->rewind(PacedBackend::Clock::now());
  phase_->findPairs(boxes, out);
}

}  // namespace bpaccel
