#include "link_model.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

HandOverTimes handOverTimes(const RunStats& s, const LinkModel& link, double clockHz) {
  HandOverTimes t;
  t.boxesSeconds = link.bytesPerBox * static_cast<double>(s.boxesSent) / link.bandwidthBytesPerSecond;
  // The port takes one box a cycle, partly under runs (overlapped loads); a
  // link slower than that adds its shortfall in full.
  const double port = static_cast<double>(s.boxesSent) / clockHz;
  t.linkExcessSeconds = std::max(0.0, t.boxesSeconds - port);
  t.loadSeconds = static_cast<double>(s.loadCycles) / clockHz + t.linkExcessSeconds;
  t.computeSeconds = static_cast<double>(s.cycles) / clockHz;
  t.resultsSeconds = link.bytesPerBeat * static_cast<double>(s.beatsReceived) / link.bandwidthBytesPerSecond;
  return t;
}

double transferSeconds(const RunStats& s, const LinkModel& link, double clockHz) {
  const HandOverTimes t = handOverTimes(s, link, clockHz);
  return static_cast<double>(s.batches) * link.latencySeconds + t.linkExcessSeconds + t.resultsSeconds;
}

void checkLink(const LinkModel& link, double clockHz, const char* who) {
  if (!(clockHz > 0) || !(link.bandwidthBytesPerSecond > 0) || link.latencySeconds < 0)
    throw std::invalid_argument(fmt::format("{}: clock and bandwidth must be positive, latency not negative", who));
}

}  // namespace bpaccel
