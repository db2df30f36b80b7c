#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "device/serial_stage.hpp"

using bpaccel::SerialStage;

TEST(SerialStage, RunsTasksInPostOrderOnAThreadOfItsOwn) {
  SerialStage stage(3);
  std::vector<int> order;  // written by the stage's thread only, read after drain
  std::vector<std::thread::id> threads;
  for (int k = 0; k < 50; ++k)
    stage.post([&, k] {
      order.push_back(k);
      threads.push_back(std::this_thread::get_id());
    });
  stage.drain();
  ASSERT_EQ(order.size(), 50u);
  for (int k = 0; k < 50; ++k) EXPECT_EQ(order[k], k);
  for (const auto id : threads) {
    EXPECT_NE(id, std::this_thread::get_id());
    EXPECT_EQ(id, threads.front());
  }
}

TEST(SerialStage, HoldsAPosterBackWhileMaxPendingTasksAreOutstanding) {
  SerialStage stage(2);
  std::promise<void> gate;
  std::shared_future<void> open = gate.get_future().share();
  std::atomic<int> ran{0};
  stage.post([&] {
    open.wait();
    ++ran;
  });
  stage.post([&] { ++ran; });  // queued behind the blocked one: two outstanding, the stage is full
  auto third = std::async(std::launch::async, [&] { stage.post([&] { ++ran; }); });
  auto room = std::async(std::launch::async, [&] { stage.waitForRoom(); });
  // Neither may return while the first task holds the stage (a broken bound returns at once).
  EXPECT_EQ(third.wait_for(std::chrono::milliseconds(100)), std::future_status::timeout);
  EXPECT_EQ(room.wait_for(std::chrono::milliseconds(0)), std::future_status::timeout);
  EXPECT_EQ(ran.load(), 0);
  gate.set_value();
  third.get();
  room.get();
  stage.drain();
  EXPECT_EQ(ran.load(), 3);
}

TEST(SerialStage, RethrowsTheFirstFailureAtDrainAfterRunningEveryTask) {
  SerialStage stage(4);
  int ran = 0;
  stage.post([&] { ++ran; });
  stage.post([&]() { ++ran; throw std::runtime_error("first"); });
  stage.post([&]() { ++ran; throw std::logic_error("second"); });
  stage.post([&] { ++ran; });  // still runs: it may own a buffer to release
  try {
    stage.drain();
    ADD_FAILURE() << "drain did not rethrow";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "first");
  }
  EXPECT_EQ(ran, 4);
  EXPECT_FALSE(stage.failed());  // forgotten once rethrown
  stage.post([&] { ++ran; });
  EXPECT_NO_THROW(stage.drain());
  EXPECT_EQ(ran, 5);
}

TEST(SerialStage, ReportsAFailureBeforeTheDrain) {
  SerialStage stage(2);
  stage.post([] { throw std::runtime_error("device"); });
  while (!stage.failed()) std::this_thread::yield();
  EXPECT_THROW(stage.drain(), std::runtime_error);
}

TEST(SerialStage, FinishesQueuedTasksWhenDestroyed) {
  std::atomic<int> ran{0};
  {
    SerialStage stage(8);
    for (int k = 0; k < 8; ++k)
      stage.post([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        ++ran;
      });
  }
  EXPECT_EQ(ran.load(), 8);
}

TEST(SerialStage, RefusesABoundOfZero) { EXPECT_THROW(SerialStage(0), std::invalid_argument); }

TEST(SerialStage, APollingStageRunsTasksInOrderAndStopsWhileItPolls) {
  std::vector<int> order;
  const auto start = std::chrono::steady_clock::now();
  {
    // Polls for up to 10 s after each task: the destructor's stop must end that at once.
    SerialStage stage(2, std::chrono::seconds(10));
    for (int k = 0; k < 20; ++k) {
      stage.post([&, k] { order.push_back(k); });
      if (k % 5 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));  // the thread is polling
    }
    stage.drain();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  ASSERT_EQ(order.size(), 20u);
  for (int k = 0; k < 20; ++k) EXPECT_EQ(order[k], k);
  EXPECT_THROW(SerialStage(1, std::chrono::microseconds(-1)), std::invalid_argument);
}
