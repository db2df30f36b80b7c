#pragma once
// The modelled link between host and device: the one place a hand-over's
// counters become time on the link and on the device.

#include "core/types.hpp"

namespace bpaccel {

/// Boxes stream through the device's load port, one box a cycle, while they
/// arrive: the load cycles are device time, and the link adds only what it is
/// slower than the port. Each hand-over (a batch of cells, or a single run)
/// pays a latency each way; result beats come back over the link. Its rates
/// are round figures of no part: the benchmark takes them from a
/// DeviceProfile (device_profile.hpp), which names the platform.
struct LinkModel {
  double bandwidthBytesPerSecond = 4e9;  // each way
  double latencySeconds = 1e-6;          // a command reaching the device, or a completion the host
  double bytesPerBox = 24;               // six keys of the device's key width
  double bytesPerBeat = 4;               // one result beat
};

/// One hand-over's modelled parts, from its counters, at the device's clock.
struct HandOverTimes {
  double boxesSeconds = 0;       // its boxes on the link
  double linkExcessSeconds = 0;  // what the link takes for them beyond the load port's one box a cycle
  double loadSeconds = 0;        // the load port's busy cycles, and the link's excess
  double computeSeconds = 0;     // the device's run cycles
  double resultsSeconds = 0;     // its result beats on the link
};
HandOverTimes handOverTimes(const RunStats& stats, const LinkModel& link, double clockHz);

/// The serial frame's transfer time, for counters summed over its hand-overs:
///   batches * latency + max(0, box bytes / bandwidth - boxes / clock) + result bytes / bandwidth
double transferSeconds(const RunStats& stats, const LinkModel& link, double clockHz);

/// Throws std::invalid_argument, naming `who`, unless the clock and the
/// bandwidth are positive and the latency not negative.
void checkLink(const LinkModel& link, double clockHz, const char* who);

}  // namespace bpaccel
