#pragma once
// A backend on a thread of its own: hand-overs are submitted, and their
// results collected later while the caller goes on.

#include <chrono>
#include <cstddef>
#include <functional>
#include <future>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "backend.hpp"
#include "serial_stage.hpp"

namespace bpaccel {

/// One hand-over's answer: what Backend::runBatch appends, for this hand-over alone.
struct BatchResult {
  std::vector<Pair> pairs;            // indices local to each cell, cells in order
  std::vector<std::size_t> cellEnds;  // pairs.size() after each cell
  RunStats stats;
};

/// A backend on a thread of its own (the device's thread) that runs
/// hand-overs one after the other in the order they were submitted, as a
/// card with a command queue would.
/// submit() returns at once with a future to poll (wait_for with a zero
/// timeout) or to wait on; an exception of the backend (a hang, a hardware
/// error, a cell over its capacity) comes out of that future's get(). The
/// cells' boxes must stay valid until their future is ready.
///
/// The backend is built, run and destroyed on that thread, from `makeBackend`:
/// a Verilated model must be evaluated by the thread that constructed it
/// (Verilator's rule; RtlBackend deadlocked at destruction otherwise). The
/// constructor returns once the backend exists, and rethrows its failure.
/// Destruction finishes every hand-over submitted before it.
///
/// `spinBeforeSleep`: the device's thread polls for the next hand-over that
/// long after each one (SerialStage), as a card takes a doorbell without a
/// wake-up; wake() starts it polling ahead of a frame's first hand-over.
class AsyncBackend {
 public:
  explicit AsyncBackend(const BackendFactory& makeBackend, std::chrono::microseconds spinBeforeSleep = {});
  ~AsyncBackend();
  AsyncBackend(const AsyncBackend&) = delete;
  AsyncBackend& operator=(const AsyncBackend&) = delete;

  const std::string& name() const { return name_; }
  std::size_t capacity() const { return capacity_; }
  bool bipartite() const { return bipartite_; }
  unsigned keyWidth() const { return keyWidth_; }
  /// Queues one hand-over of `cells` (each at most capacity() boxes), with
  /// their bipartite splits as Backend::runBatch takes them (empty: none).
  std::future<BatchResult> submit(std::span<const std::span<const KeyBox>> cells,
                                  std::span<const std::size_t> splits = {});
  /// Wakes the device's thread, so that it polls (with spinBeforeSleep) by
  /// the time the next hand-over comes; a no-op on its queue. Returns at once.
  void wake();
  /// The same, and returns once the device's thread is awake (and polling,
  /// with spinBeforeSleep), after every hand-over submitted before.
  void awaken();

 private:
  std::unique_ptr<Backend> backend_;  // built, used and destroyed on the stage's thread only
  std::string name_;
  std::size_t capacity_ = 0;
  bool bipartite_ = false;
  unsigned keyWidth_ = 32;
  SerialStage stage_;  // last: its thread stops first, after the hand-overs queued
};

}  // namespace bpaccel
