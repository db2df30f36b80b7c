#pragma once
// What a caller may learn of a frame's timing: an observer that BroadPhase
// tells at the end of each findPairs. Without one, BroadPhase reads no clock.

#include <vector>

#include "../core/types.hpp"

namespace bpaccel {

/// Host time of one findPairs call, by part (measured with a steady clock).
struct HostTimes {
  double convertSeconds = 0;    // float to key conversion and validation
  double partitionSeconds = 0;  // partition build (k-d tree or grid, with the grid's packing of its cells'
                                // boxes), without the cells' processing
  double cellsSeconds = 0;      // packing, backend runs, decoding and filtering
  double backendSeconds = 0;    // inside the backend (simulating the device, or the cpu test itself) and
                                // waiting for it, summed over the worker threads
  double totalSeconds = 0;      // all of the above (conversion only when the input was floats)
};

/// One hand-over to the device (a batch of cells, or a single run), as measured.
struct HandOverRecord {
  /// Host time from the frame's start until this hand-over's boxes were
  /// packed, with the device's time taken out.
  double readySeconds = 0;
  /// Host time to decode and filter this hand-over's pairs.
  double decodeSeconds = 0;
  RunStats stats;  // this hand-over's counters (cycles from rtl or model)
};

/// The timing of one findPairs call.
struct FrameTiming {
  HostTimes times;
  /// The hand-overs in order; with several threads, each worker's follow the previous worker's.
  std::vector<HandOverRecord> handOvers;
};

/// Told the timing of every frame that ends normally, on the thread that
/// called findPairs. It costs the frame the clock reads; none without it.
class BroadPhaseObserver {
 public:
  virtual ~BroadPhaseObserver() = default;
  virtual void frameFinished(const FrameTiming& frame) = 0;
};

/// An observer that keeps the last frame's timing.
class LastFrameTiming final : public BroadPhaseObserver {
 public:
  void frameFinished(const FrameTiming& frame) override {
    last_.times = frame.times;
    last_.handOvers.assign(frame.handOvers.begin(), frame.handOvers.end());  // keeps its storage
  }
  const FrameTiming& last() const { return last_; }
  const HostTimes& times() const { return last_.times; }
  const std::vector<HandOverRecord>& handOvers() const { return last_.handOvers; }

 private:
  FrameTiming last_;
};

}  // namespace bpaccel
