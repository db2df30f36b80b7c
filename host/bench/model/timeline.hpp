#pragma once
// A frame of the accelerated broad phase as a pipeline: the host's measured
// work, a modelled link and a modelled device, overlapped.

#include <cstddef>
#include <vector>

#include "broad_phase/broad_phase_config.hpp"
#include "broad_phase/frame_observer.hpp"
#include "core/types.hpp"
#include "link_model.hpp"

namespace bpaccel {

/// What the device, the link and the host's schedule are modelled with.
struct PipelineModel {
  double clockHz = 100e6;  // the device's
  LinkModel link;
  std::size_t batchesInFlight = kBatchesInFlight;  // the host's bound (at least 1)
  /// The producer decodes the answers itself (HandOvers::Polled): after each
  /// hand-over those that have arrived, and for room or at the frame's end
  /// it waits for the oldest. Otherwise a decoder thread does (Asynchronous).
  bool decodeOnProducer = false;
};

/// One hand-over's modelled parts (handOverTimes) at the model's clock.
inline HandOverTimes handOverTimes(const RunStats& stats, const PipelineModel& model) {
  return handOverTimes(stats, model.link, model.clockHz);
}

/// An interval of one lane of the timeline, for the plot.
struct Span {
  double start = 0, end = 0;
  std::size_t run = 0;
};

/// A frame's timeline, as BroadPhase's asynchronous hand-overs
/// (HandOvers::Asynchronous) run it, built from a synchronous run's measured
/// parts. The host is two threads: the producer makes runs (keys, partition,
/// packing), as measured but without the decoding the synchronous run did in
/// between, and hands each over; the decoder decodes each run's results, in
/// order, once they have arrived. With batchesInFlight runs handed over and
/// not yet decoded, the producer waits for the oldest one's decoding before
/// it hands over the next (and all its later work moves by that wait).
/// With decodeOnProducer there is no decoder thread: the producer decodes
/// (see PipelineModel), and its later work moves by each decode and wait.
/// A run waits for the device and the link to be free: its boxes stream in
/// through the load port, as fast as the slower of the link and the port
/// (one box a cycle), the device computes, result beats return over the
/// link, and a completion reaches the host after the latency.
struct FrameTimeline {
  double frameSeconds = 0;   // the end of the last decode (or of the producer, if later)
  double producerSeconds = 0;
  std::vector<Span> produce, link, device, decode;
};

/// `hostSeconds`: the frame's measured host time (device simulation excluded),
/// decoding included, as the serial run spent it.
FrameTimeline modelPipeline(const std::vector<HandOverRecord>& runs, double hostSeconds, const PipelineModel& model);

}  // namespace bpaccel
