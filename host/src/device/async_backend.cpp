#include "async_backend.hpp"

#include <limits>
#include <stdexcept>
#include <utility>

namespace bpaccel {

// The stage's bound is not the host's: a caller may submit as many hand-overs as it likes.
AsyncBackend::AsyncBackend(const BackendFactory& makeBackend, std::chrono::microseconds spinBeforeSleep)
    : stage_(std::numeric_limits<std::size_t>::max(), spinBeforeSleep) {
  stage_.post([this, &makeBackend] {
    backend_ = makeBackend();
    if (!backend_) throw std::invalid_argument("async backend: the backend factory gave no backend");
    name_ = backend_->name();
    capacity_ = backend_->capacity();
    bipartite_ = backend_->bipartite();
    keyWidth_ = backend_->keyWidth();
  });
  stage_.drain();  // the backend exists (or its failure is rethrown here, while `makeBackend` still does)
}

// The backend goes on the thread that built it, after every hand-over submitted before.
AsyncBackend::~AsyncBackend() {
  stage_.post([this] { backend_.reset(); });
  try {
    stage_.drain();
  } catch (...) {  // a failure the destructor cannot report; the backend is gone all the same
  }
}

std::future<BatchResult> AsyncBackend::submit(std::span<const std::span<const KeyBox>> cells,
                                              std::span<const std::size_t> splits) {
  auto job = std::make_shared<std::packaged_task<BatchResult()>>(
      [this, cells = std::vector(cells.begin(), cells.end()), splits = std::vector(splits.begin(), splits.end())] {
        BatchResult out;
        backend_->runBatch(cells, splits, out.pairs, out.cellEnds, out.stats);
        return out;
      });
  auto result = job->get_future();
  stage_.post([job] { (*job)(); });  // a failure goes to this hand-over's future, not the stage
  return result;
}

void AsyncBackend::wake() {
  stage_.post([] {});
}

void AsyncBackend::awaken() {
  wake();
  stage_.drain();  // hand-overs fail through their futures, not the stage: nothing to rethrow
}

}  // namespace bpaccel
