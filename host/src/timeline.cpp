#include "timeline.hpp"

#include <algorithm>
#include <stdexcept>

namespace bpaccel {

HandOverTimes handOverTimes(const RunStats& s, const PipelineModel& model) {
  HandOverTimes t;
  t.boxesSeconds = model.bytesPerBox * static_cast<double>(s.boxesSent) / model.bandwidthBytesPerSecond;
  // The port takes one box a cycle, partly under runs (overlapped loads);
  // a link slower than that adds its shortfall in full.
  const double port = static_cast<double>(s.boxesSent) / model.clockHz;
  t.loadSeconds = static_cast<double>(s.loadCycles) / model.clockHz + std::max(0.0, t.boxesSeconds - port);
  t.computeSeconds = static_cast<double>(s.cycles) / model.clockHz;
  t.resultsSeconds = model.bytesPerBeat * static_cast<double>(s.beatsReceived) / model.bandwidthBytesPerSecond;
  return t;
}

FrameTimeline modelPipeline(const std::vector<RunRecord>& runs, double hostSeconds, const PipelineModel& model) {
  if (!(model.clockHz > 0) || !(model.bandwidthBytesPerSecond > 0) || model.latencySeconds < 0)
    throw std::invalid_argument("pipeline model: clock and bandwidth must be positive, latency not negative");
  if (model.batchesInFlight < 1) throw std::invalid_argument("pipeline model: at least one batch in flight");
  FrameTimeline t;
  double decodedBefore = 0;  // decoding the serial run did before this run was ready
  double waited = 0;         // the producer's waits for a free batch so far
  double linkFree = 0, deviceFree = 0, decodeFree = 0, produceStart = 0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunRecord& r = runs[i];
    const RunStats& s = r.stats;
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

    const auto [boxes, load, compute, results] = handOverTimes(s, model);
    const double start = std::max({ready + model.latencySeconds, linkFree, deviceFree});
    t.link.push_back({start, start + boxes, i});
    if (results > 0) t.link.push_back({start + load, start + load + results, i});
    t.device.push_back({start, start + load + compute, i});
    deviceFree = start + load + compute;
    linkFree = std::max(start + boxes, start + load + results);
    const double arrived = std::max(deviceFree, start + load + results) + model.latencySeconds;
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
