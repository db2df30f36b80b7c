#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <stdexcept>
#include <thread>
#include <vector>

#include "device/async_backend.hpp"
#include "device/model_backend.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

TEST(AsyncBackend, GivesEachHandOverWhatTheBackendGivesInSubmissionOrder) {
  ModelBackend direct(DeviceParams::seed(2, 16, 5));
  AsyncBackend async([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 16, 5)); });
  EXPECT_EQ(async.name(), "model");
  EXPECT_EQ(async.capacity(), 16u);
  std::vector<std::vector<KeyBox>> scenes;
  for (unsigned seed = 0; seed < 6; ++seed) scenes.push_back(keysOf(scatteredBoxes(40, seed, 0.0f, 30.0f, 1.0f, 4.0f)));
  // Hand-overs of one to three cells of up to 16 boxes each, all submitted before any is waited for.
  std::vector<std::vector<std::span<const KeyBox>>> handOvers;
  for (std::size_t h = 0; h < scenes.size(); ++h) {
    std::vector<std::span<const KeyBox>> cells;
    for (std::size_t c = 0; c <= h % 3; ++c) cells.push_back(std::span<const KeyBox>(scenes[h]).subspan(8 * c, 16));
    handOvers.push_back(cells);
  }
  std::vector<std::future<BatchResult>> results;
  for (const auto& cells : handOvers) results.push_back(async.submit(cells));
  for (std::size_t h = 0; h < handOvers.size(); ++h) {
    // Polling: the result arrives without anyone waiting for it.
    while (results[h].wait_for(std::chrono::seconds(0)) != std::future_status::ready) std::this_thread::yield();
    const BatchResult got = results[h].get();
    BatchResult expected;
    direct.runBatch(handOvers[h], expected.pairs, expected.cellEnds, expected.stats);
    EXPECT_EQ(got.pairs, expected.pairs) << "hand-over " << h;
    EXPECT_EQ(got.cellEnds, expected.cellEnds) << "hand-over " << h;
    EXPECT_EQ(got.stats.deviceCycles(), expected.stats.deviceCycles()) << "hand-over " << h;
    EXPECT_EQ(got.stats.runs, expected.stats.runs) << "hand-over " << h;
    EXPECT_GT(got.stats.runs, 0u);
  }
}

TEST(AsyncBackend, PassesTheDevicesFailureToItsHandOverOnlyAndGoesOn) {
  AsyncBackend async([] { return std::make_unique<ModelBackend>(DeviceParams::seed(2, 16, 5)); });
  const auto keys = keysOf(scatteredBoxes(20, 3, 0.0f, 10.0f, 1.0f, 4.0f));
  const std::vector<std::span<const KeyBox>> tooLarge = {std::span<const KeyBox>(keys)};  // 20 > capacity 16
  const std::vector<std::span<const KeyBox>> fits = {std::span<const KeyBox>(keys).first(16)};
  auto bad = async.submit(tooLarge);
  auto good = async.submit(fits);
  EXPECT_THROW(bad.get(), std::length_error);
  EXPECT_EQ(good.get().cellEnds.size(), 1u);
}

TEST(AsyncBackend, RethrowsAFailedDeviceConstructionFromItsOwnConstructor) {
  EXPECT_THROW(AsyncBackend([]() -> std::unique_ptr<Backend> { throw std::runtime_error("no device"); }),
               std::runtime_error);
  EXPECT_THROW(AsyncBackend([] { return std::unique_ptr<Backend>(); }), std::invalid_argument);
}
