#include "timeline.hpp"

#include <algorithm>
#include <stdexcept>

namespace bpaccel {

namespace {

// The link and the device, shared by both hosts: each run takes them in turn.
class DeviceLanes {
 public:
  DeviceLanes(const PipelineModel& model, FrameTimeline& t) : model_(model), t_(t) {}
  // Run i handed over at `ready`: returns when its answer reaches the host.
  double run(std::size_t i, const RunStats& s, double ready) {
    const auto [boxes, excess, load, compute, results] = handOverTimes(s, model_);
    const double start = std::max({ready + model_.link.latencySeconds, linkFree_, deviceFree_});
    t_.link.push_back({start, start + boxes, i});
    if (results > 0) t_.link.push_back({start + load, start + load + results, i});
    t_.device.push_back({start, start + load + compute, i});
    deviceFree_ = start + load + compute;
    linkFree_ = std::max(start + boxes, start + load + results);
    return std::max(deviceFree_, start + load + results) + model_.link.latencySeconds;
  }

 private:
  const PipelineModel& model_;
  FrameTimeline& t_;
  double linkFree_ = 0, deviceFree_ = 0;
};

// HandOvers::Polled: one host thread produces and decodes, in the code's
// order (BroadPhase::Worker::handOverPolled, decodeOldest, finish).
FrameTimeline modelPolled(const std::vector<HandOverRecord>& runs, double hostSeconds, const PipelineModel& model) {
  FrameTimeline t;
  DeviceLanes lanes(model, t);
  std::vector<double> arrived;
  arrived.reserve(runs.size());
  double now = 0;            // the producer's clock
  double ownBefore = 0;      // the producer's own work (the serial run's, less its decoding) up to the last run
  double decodedBefore = 0;  // decoding the serial run did before this run was ready
  std::size_t decoded = 0;
  const auto decodeOldest = [&] {
    const double start = std::max(now, arrived[decoded]);
    now = start + runs[decoded].decodeSeconds;
    t.decode.push_back({start, now, decoded});
    ++decoded;
  };
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const double own = std::max(ownBefore, runs[i].readySeconds - decodedBefore);
    decodedBefore += runs[i].decodeSeconds;
    t.produce.push_back({now, now + own - ownBefore, i});
    now += own - ownBefore;
    ownBefore = own;
    if (i - decoded == model.batchesInFlight) decodeOldest();
    arrived.push_back(lanes.run(i, runs[i].stats, now));
    while (decoded < i + 1 && arrived[decoded] <= now) decodeOldest();
  }
  const double tail = std::max(0.0, hostSeconds - decodedBefore - ownBefore);
  if (tail > 0) t.produce.push_back({now, now + tail, runs.size()});
  now += tail;
  t.producerSeconds = now;
  while (decoded < runs.size()) decodeOldest();
  t.frameSeconds = now;
  return t;
}

}  // namespace

FrameTimeline modelPipeline(const std::vector<HandOverRecord>& runs, double hostSeconds, const PipelineModel& model) {
  checkLink(model.link, model.clockHz, "pipeline model");
  if (model.batchesInFlight < 1) throw std::invalid_argument("pipeline model: at least one batch in flight");
  if (model.decodeOnProducer) return modelPolled(runs, hostSeconds, model);
  FrameTimeline t;
  DeviceLanes lanes(model, t);
  double decodedBefore = 0;  // decoding the serial run did before this run was ready
  double waited = 0;         // the producer's waits for a free batch so far
  double decodeFree = 0, produceStart = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const HandOverRecord& r = runs[i];
    // The producer no longer decodes: each run is ready that much earlier,
    // and as much later as it waited for room.
    double ready = std::max(0.0, r.readySeconds - decodedBefore) + waited;
    if (i >= model.batchesInFlight) {
      const double free = t.decode[i - model.batchesInFlight].end;
      if (free > ready) {
        waited += free - ready;
        ready = free;
      }
    }
    decodedBefore += r.decodeSeconds;
    t.produce.push_back({produceStart, ready, i});
    produceStart = ready;

    const double arrived = lanes.run(i, r.stats, ready);
    const double decodeStart = std::max(arrived, decodeFree);
    decodeFree = decodeStart + r.decodeSeconds;
    t.decode.push_back({decodeStart, decodeFree, i});
  }
  t.producerSeconds = std::max(produceStart, hostSeconds - decodedBefore + waited);
  if (t.producerSeconds > produceStart) t.produce.push_back({produceStart, t.producerSeconds, runs.size()});
  t.frameSeconds = std::max(decodeFree, t.producerSeconds);
  return t;
}

}  // namespace bpaccel
