#pragma once
// The broad phase's clock reads, made only when an observer wants the timing
// (BroadPhaseObserver): otherwise now() reads no clock and every figure is 0.

#include <chrono>
#include <vector>

#include "frame_observer.hpp"

namespace bpaccel {

class FrameClock {
 public:
  using Clock = std::chrono::steady_clock;
  explicit FrameClock(bool on = false) : on_(on) {}
  bool on() const { return on_; }
  Clock::time_point now() const { return on_ ? Clock::now() : Clock::time_point{}; }
  static double seconds(Clock::time_point from, Clock::time_point to) {
    return std::chrono::duration<double>(to - from).count();
  }

 private:
  bool on_;
};

/// One worker's hand-overs of a frame: when each was ready, how long its
/// decoding took, and the time spent in or waiting for the backend (not host work).
class HandOverTimer {
 public:
  using Clock = FrameClock::Clock;
  explicit HandOverTimer(bool on = false) : clock_(on) {}
  bool on() const { return clock_.on(); }
  Clock::time_point now() const { return clock_.now(); }
  void startFrame(Clock::time_point start) {
    frameStart_ = start;
    backendSeconds_ = 0;
    records_.clear();
  }
  /// Host time from the frame's start to `t`, the backend's time taken out.
  double readySeconds(Clock::time_point t) const { return FrameClock::seconds(frameStart_, t) - backendSeconds_; }
  /// Time in the backend or waiting for it (the device), from `from` to `to`: not host work.
  void addBackendTime(Clock::time_point from, Clock::time_point to) {
    backendSeconds_ += FrameClock::seconds(from, to);
  }
  /// The same from `from` to now (a clock read only when on).
  void addBackendTimeSince(Clock::time_point from) {
    if (on()) addBackendTime(from, Clock::now());
  }
  void record(const HandOverRecord& r) {
    if (on()) records_.push_back(r);
  }
  double backendSeconds() const { return backendSeconds_; }
  const std::vector<HandOverRecord>& records() const { return records_; }

 private:
  FrameClock clock_;
  Clock::time_point frameStart_{};
  double backendSeconds_ = 0;             // the producer's (written on its thread only)
  std::vector<HandOverRecord> records_;   // written by whichever thread decodes
};

}  // namespace bpaccel
