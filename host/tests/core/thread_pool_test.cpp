#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "core/keys.hpp"
#include "core/thread_pool.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

TEST(ThreadPool, ForEachRunsEveryIndexExactlyOnceOnOneAndTwoThreads) {
  for (std::size_t threads : {1, 2})
    for (std::size_t count : {0, 1, 2, 3, 1000}) {
      ThreadPool pool(threads);
      std::vector<std::atomic<int>> seen(count);
      std::vector<std::atomic<int>> byThread(threads);
      pool.forEach(count, [&](std::size_t k) {
        ++seen[k];
        ASSERT_LT(pool.thisThread(), threads);
        ++byThread[pool.thisThread()];
      });
      for (std::size_t k = 0; k < count; ++k) EXPECT_EQ(seen[k], 1) << "k=" << k << " threads " << threads;
    }
}

TEST(ThreadPool, ForPartsCutsTheRangeIntoContiguousPartsThatCoverItOnce) {
  for (std::size_t threads : {1, 2, 3})
    for (std::size_t count : {0, 1, 2, 5, 1001}) {
      ThreadPool pool(threads);
      const std::size_t parts = pool.partsOf(count);
      EXPECT_EQ(parts, std::max<std::size_t>(1, std::min(threads, count)));
      std::vector<std::pair<std::size_t, std::size_t>> got(parts);
      pool.forParts(count, [&](std::size_t k, std::size_t begin, std::size_t end) { got[k] = {begin, end}; });
      std::size_t next = 0;
      for (const auto& [begin, end] : got) {
        EXPECT_EQ(begin, next) << "threads " << threads << " count " << count;
        EXPECT_LE(begin, end);
        next = end;
      }
      EXPECT_EQ(next, count);
    }
}

TEST(ThreadPool, RethrowsAFailureOfAnyTaskAndStaysUsable) {
  ThreadPool pool(2);
  EXPECT_THROW(pool.forEach(100, [](std::size_t k) { if (k == 77) throw std::runtime_error("77"); }),
               std::runtime_error);
  std::atomic<std::size_t> sum = 0;
  pool.forEach(10, [&](std::size_t k) { sum += k; });
  EXPECT_EQ(sum, 45u);
  EXPECT_THROW(ThreadPool(0), std::invalid_argument);
}

TEST(ToKeys, OnAPoolGivesTheSerialKeysAndBoundsForEveryCount) {
  ThreadPool pool(2);
  for (std::size_t n : {1, 2, 3, 7, 8, 9, 31, 1000})
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 11)) {
      std::vector<KeyBox> serial, parallel;
      KeyBounds serialBounds, parallelBounds;
      toKeys(boxes, serial, serialBounds);
      toKeys(boxes, parallel, parallelBounds, pool);
      const std::string label = name + " n=" + std::to_string(n);
      ASSERT_EQ(parallel.size(), serial.size()) << label;
      for (std::size_t i = 0; i < n; ++i) {
        EXPECT_EQ(parallel[i].min, serial[i].min) << label << " box " << i;
        EXPECT_EQ(parallel[i].max, serial[i].max) << label << " box " << i;
      }
      EXPECT_EQ(parallelBounds.lo, serialBounds.lo) << label;
      EXPECT_EQ(parallelBounds.hi, serialBounds.hi) << label;
    }
}

TEST(ToKeys, OnAPoolNamesTheFirstBadBoxEvenWhenALaterPartHasOneToo) {
  ThreadPool pool(2);
  std::vector<Aabb> boxes = scatteredBoxes(1000, 5, 0, 100, 0.5f, 2);
  boxes[900].min[1] = boxes[900].max[1] + 1;  // the second part's
  boxes[600].min[2] = boxes[600].max[2] + 1;  // also the second part's, but first
  std::vector<KeyBox> keys;
  KeyBounds bounds;
  try {
    toKeys(boxes, keys, bounds, pool);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("object 600:"), std::string::npos) << e.what();
  }
  boxes[400].min[0] = boxes[400].max[0] + 1;  // now the first part has the first
  try {
    toKeys(boxes, keys, bounds, pool);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("object 400:"), std::string::npos) << e.what();
  }
}
