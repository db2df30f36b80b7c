#include "thread_pool.hpp"

#include <algorithm>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace bpaccel {

struct ThreadPool::Arena {
  explicit Arena(std::size_t threads) : arena(static_cast<int>(threads)) {}
  tbb::task_arena arena;
};

ThreadPool::ThreadPool(std::size_t threads) : threads_(threads) {
  if (threads < 1) throw std::invalid_argument("thread pool: at least one thread");
  if (threads > 1) arena_ = std::make_unique<Arena>(threads);
}

ThreadPool::~ThreadPool() = default;

void ThreadPool::forEach(std::size_t count, const std::function<void(std::size_t)>& f) {
  if (!arena_ || count < 2) {
    for (std::size_t k = 0; k < count; ++k) f(k);
    return;
  }
  // One item a task, stolen as threads run out of work: items may differ
  // widely in cost (a cell of ten boxes, a cell of thousands).
  arena_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t k = r.begin(); k < r.end(); ++k) f(k);
                      });
  });
}

std::size_t ThreadPool::partsOf(std::size_t count) const { return std::max<std::size_t>(1, std::min(threads_, count)); }

void ThreadPool::forParts(std::size_t count,
                          const std::function<void(std::size_t, std::size_t, std::size_t)>& f) {
  const std::size_t parts = partsOf(count);
  const auto run = [&](std::size_t k) { f(k, count * k / parts, count * (k + 1) / parts); };
  if (!arena_ || parts == 1) {
    for (std::size_t k = 0; k < parts; ++k) run(k);
    return;
  }
  arena_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, parts, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t k = r.begin(); k < r.end(); ++k) run(k);
                      },
                      tbb::simple_partitioner());
  });
}

std::size_t ThreadPool::thisThread() const {
  if (!arena_) return 0;
  const int index = tbb::this_task_arena::current_thread_index();
  return index < 0 ? 0 : static_cast<std::size_t>(index);
}

}  // namespace bpaccel
