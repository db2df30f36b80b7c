#pragma once
// One stage of a pipeline on a thread of its own: tasks run one after the
// other, in the order they were posted, while the poster goes on.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <stop_token>
#include <thread>

namespace bpaccel {

/// One turn of a polling loop: a pause for the core, and the core yielded
/// to any thread waiting for it (a thread polling past its time held a
/// paced device up to 0.8 ms in the bench before it yielded).
inline void pollPause() {
  __builtin_ia32_pause();
  std::this_thread::yield();
}

/// Runs posted tasks in order on one thread. At most `maxPending` tasks are
/// outstanding (posted, not yet finished): waitForRoom() blocks until one more
/// may be posted, so a poster that recycles a fixed set of buffers knows the
/// oldest one is free again. A task that throws does not stop the stage: the
/// first exception is kept and rethrown by drain(), and the tasks after it
/// still run (each may own a resource that must be released).
///
/// `spinBeforeSleep`: after each task the thread polls its queue for that
/// long before it sleeps. A stage that stands for hardware (a device that
/// takes a doorbell, not a wake-up) uses it: waking a sleeping thread took
/// 22-62 us on the 2-core virtual machines here, about a hand-over's worth.
/// It costs a core while it polls, but yields it each turn (pollPause);
/// 0 (the default) never polls.
class SerialStage {
 public:
  explicit SerialStage(std::size_t maxPending, std::chrono::microseconds spinBeforeSleep = {});
  /// Runs every task posted before it, then stops the thread.
  ~SerialStage();
  SerialStage(const SerialStage&) = delete;
  SerialStage& operator=(const SerialStage&) = delete;

  std::size_t maxPending() const { return maxPending_; }
  /// Blocks until fewer than maxPending tasks are outstanding.
  void waitForRoom();
  /// Queues `task`; blocks first, as waitForRoom, if the stage is full.
  void post(std::function<void()> task);
  /// Blocks until every posted task has finished; then rethrows (and forgets)
  /// the first exception a task threw since the last drain.
  void drain();
  /// Whether a task has thrown since the last drain (the poster may stop early).
  bool failed();

 private:
  void serve(std::stop_token stop);

  std::size_t maxPending_;
  std::chrono::microseconds spinBeforeSleep_;
  std::atomic<std::size_t> queued_{0};  // tasks_.size(), for the thread to poll without the lock
  std::mutex mutex_;
  std::condition_variable_any taskReady_;  // the stage's thread waits here
  std::condition_variable finished_;       // posters wait here for room, or for the end
  std::deque<std::function<void()>> tasks_;
  std::size_t outstanding_ = 0;  // queued or running
  std::exception_ptr firstFailure_;
  std::jthread thread_;  // last: it starts once the members it uses exist, and stops first
};

}  // namespace bpaccel
