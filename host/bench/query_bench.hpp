#pragma once
// Broad-phase ray and box queries: btDbvtBroadphase against bpaccel::BulletDropIn
// on the bouncing cube's proxies, every answer checked against Bullet's own
// tests proxy by proxy.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scenes/scene.hpp"

namespace bpaccel {

struct QueryBenchConfig {
  std::vector<std::size_t> objectCounts;  // one row each
  std::size_t frames = 3;   // steps of the world (setAabb and calculateOverlappingPairs) before the queries
  std::size_t perKind = 1000;  // queries of each kind (two ray lengths, boxes), a round
  std::size_t rounds = 5;   // each round times every method once, in a shuffled order
  SceneConfig scene;        // objects is set per row
};

/// One table row per object count; throws std::runtime_error when the
/// drop-in reports a proxy Bullet's test refuses or misses one it accepts, or
/// when btDbvtBroadphase misses one.
nlohmann::json runQueryBench(const QueryBenchConfig& config, const std::function<void(const std::string&)>& progress);
/// The rows as a text table.
std::string queryTable(const nlohmann::json& queries);

}  // namespace bpaccel
