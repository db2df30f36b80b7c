#include "async_backend.hpp"

#include <exception>
#include <stdexcept>
#include <utility>

namespace bpaccel {

AsyncBackend::AsyncBackend(const DeviceFactory& makeDevice) {
  std::promise<void> built;
  auto ready = built.get_future();
  worker_ = std::jthread([this, &makeDevice, built = std::move(built)](std::stop_token stop) mutable {
    std::unique_ptr<Backend> device;
    try {
      device = makeDevice();
      if (!device) throw std::invalid_argument("async backend: the device factory gave no device");
      name_ = device->name();
      capacity_ = device->capacity();
      bipartite_ = device->bipartite();
      keyWidth_ = device->keyWidth();
    } catch (...) {
      built.set_exception(std::current_exception());
      return;
    }
    built.set_value();  // from here on the constructor may have returned: `makeDevice` is gone
    serve(std::move(stop), *device);
  });
  ready.get();  // the device exists (or its failure is rethrown here)
}

// The jthread asks the worker to stop and joins it; the worker drains the
// queue first, so no submitted hand-over is dropped.
AsyncBackend::~AsyncBackend() = default;

std::future<BatchResult> AsyncBackend::submit(std::span<const std::span<const KeyBox>> cells,
                                              std::span<const std::size_t> splits) {
  return enqueue(Job{{cells.begin(), cells.end()}, {splits.begin(), splits.end()}, {}});
}

std::future<BatchResult> AsyncBackend::enqueue(Job job) {
  auto result = job.result.get_future();
  {
    const std::lock_guard lock(mutex_);
    jobs_.push_back(std::move(job));
  }
  jobReady_.notify_one();
  return result;
}

void AsyncBackend::serve(std::stop_token stop, Backend& device) {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      // Returns on a job, or on a stop request; a stop with jobs left still serves them.
      jobReady_.wait(lock, stop, [this] { return !jobs_.empty(); });
      if (jobs_.empty()) return;
      job = std::move(jobs_.front());
      jobs_.pop_front();
    }
    BatchResult out;
    try {
      device.runBatch(job.cells, job.splits, out.pairs, out.cellEnds, out.stats);
      job.result.set_value(std::move(out));
    } catch (...) {
      job.result.set_exception(std::current_exception());
    }
  }
}

}  // namespace bpaccel
