#pragma once
// The threads a broad phase's host work shares: the key conversion, the
// partition and the cells (oneTBB underneath, in an arena of its own).

#include <cstddef>
#include <functional>
#include <memory>

namespace bpaccel {

/// A fixed number of threads, the caller's among them. With one thread the
/// loops run on the caller, with no task machinery at all.
class ThreadPool {
 public:
  explicit ThreadPool(std::size_t threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  std::size_t threads() const { return threads_; }
  /// f(k) for every k in [0, count), spread over the threads (any order,
  /// each k once); returns when all are done and rethrows the first failure.
  void forEach(std::size_t count, const std::function<void(std::size_t)>& f);
  /// f(begin, end) over [0, count) cut into one contiguous part a thread
  /// (fewer when count is small), part k being [count*k/T, count*(k+1)/T).
  void forParts(std::size_t count, const std::function<void(std::size_t part, std::size_t begin, std::size_t end)>& f);
  /// How many parts forParts cuts `count` into.
  std::size_t partsOf(std::size_t count) const;
  /// The calling thread's index, 0 .. threads() - 1, inside forEach and forParts (0 outside).
  std::size_t thisThread() const;

 private:
  struct Arena;
  std::size_t threads_;
  std::unique_ptr<Arena> arena_;  // none with one thread
};

}  // namespace bpaccel
