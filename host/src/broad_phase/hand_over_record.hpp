#pragma once
// What BroadPhase records of each hand-over to the device, for a model of the
// frame's pipeline (the benchmark's timeline).

#include <cstddef>

#include "../core/types.hpp"

namespace bpaccel {

/// One backend run of a frame, as BroadPhase recorded it.
struct RunRecord {
  /// Measured: host time from the frame's start until this run's boxes were
  /// packed, with the device's simulation taken out.
  double readySeconds = 0;
  /// Measured: host time to decode and filter this run's pairs.
  double decodeSeconds = 0;
  RunStats stats;  // this run's counters (cycles from rtl or model)
};

/// Hand-overs the asynchronous host keeps handed over and not yet decoded
/// (BroadPhase, HandOvers::Asynchronous): with that many out, the producer
/// waits for the oldest to be decoded before it hands over the next.
inline constexpr std::size_t kBatchesInFlight = 3;

}  // namespace bpaccel
