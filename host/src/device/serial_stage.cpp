#include "serial_stage.hpp"

#include <stdexcept>
#include <utility>

namespace bpaccel {

SerialStage::SerialStage(std::size_t maxPending, std::chrono::microseconds spinBeforeSleep)
    : maxPending_(maxPending), spinBeforeSleep_(spinBeforeSleep) {
  if (maxPending < 1) throw std::invalid_argument("serial stage: at least one task must be allowed outstanding");
  if (spinBeforeSleep.count() < 0) throw std::invalid_argument("serial stage: a negative time to poll before sleeping");
  thread_ = std::jthread([this](std::stop_token stop) { serve(std::move(stop)); });
}

// The jthread asks the thread to stop and joins it; the thread runs what is queued first.
SerialStage::~SerialStage() = default;

void SerialStage::waitForRoom() {
  std::unique_lock lock(mutex_);
  finished_.wait(lock, [this] { return outstanding_ < maxPending_; });
}

void SerialStage::post(std::function<void()> task) {
  {
    std::unique_lock lock(mutex_);
    finished_.wait(lock, [this] { return outstanding_ < maxPending_; });
    tasks_.push_back(std::move(task));
    queued_.store(tasks_.size(), std::memory_order_release);
    ++outstanding_;
  }
  taskReady_.notify_one();
}

void SerialStage::drain() {
  std::exception_ptr failure;
  {
    std::unique_lock lock(mutex_);
    finished_.wait(lock, [this] { return outstanding_ == 0; });
    failure = std::exchange(firstFailure_, nullptr);
  }
  if (failure) std::rethrow_exception(failure);
}

bool SerialStage::failed() {
  const std::lock_guard lock(mutex_);
  return firstFailure_ != nullptr;
}

void SerialStage::serve(std::stop_token stop) {
  for (;;) {
    if (spinBeforeSleep_.count() > 0) {
      const auto until = std::chrono::steady_clock::now() + spinBeforeSleep_;
      while (queued_.load(std::memory_order_acquire) == 0 && !stop.stop_requested() &&
             std::chrono::steady_clock::now() < until) {
        pollPause();
      }
    }
    std::function<void()> task;
    {
      std::unique_lock lock(mutex_);
      // Returns on a task, or on a stop request; a stop with tasks left still runs them.
      taskReady_.wait(lock, stop, [this] { return !tasks_.empty(); });
      if (tasks_.empty()) return;
      task = std::move(tasks_.front());
      tasks_.pop_front();
      queued_.store(tasks_.size(), std::memory_order_release);
    }
    std::exception_ptr failure;
    try {
      task();
    } catch (...) {
      failure = std::current_exception();
    }
    {
      const std::lock_guard lock(mutex_);
      if (failure && !firstFailure_) firstFailure_ = failure;
      --outstanding_;
    }
    finished_.notify_all();
  }
}

}  // namespace bpaccel
