#pragma once
// The bouncing-cube benchmark: Bullet's broad phases against the accelerator.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene.hpp"
#include "types.hpp"

namespace bpaccel {

/// Modelled link between host and accelerator: bytes over a bandwidth plus a latency per run.
struct LinkModel {
  double bandwidthBytesPerSecond = 4e9;  // a PCIe Gen3 x4 link's order of magnitude
  double latencySecondsPerRun = 1e-6;    // one command and one completion per run
  double seconds(const RunStats& s, std::size_t beatBytes) const;
};

struct BenchConfig {
  std::vector<std::size_t> objectCounts{100, 1000, 8000};
  std::vector<std::optional<std::size_t>> cellSizes{std::nullopt, 16, 32, 64, 128, 256};
  std::string accelBackend = "rtl";  // rtl or model: where the device's cycles come from
  std::size_t frames = 50;           // timed frames per row
  std::size_t warmup = 5;            // frames simulated and run but not timed
  SceneConfig scene;                 // objects is set per row
  double clockHz = 100e6;
  std::string clockSource = "default 100 MHz";
  LinkModel link;
  std::string jsonPath = "results/bench.json";
  bool includeSimple = true;         // btSimpleBroadphase is O(n^2): skip for huge scenes
  /// Test hook: applied to every accelerator pair set before validation, so a
  /// test can prove that a wrong answer fails the run.
  std::function<void(std::vector<Pair>&)> tamper;
};

/// Per-frame samples of one method in one row.
struct MethodSamples {
  std::string name;
  std::string kind;                       // bullet, accelerator, cpu
  std::optional<std::size_t> cellSize;
  std::vector<double> frameSeconds;       // what the table reports
  std::vector<double> hostSeconds;        // accelerator: measured host part
  std::vector<double> deviceSeconds;      // accelerator: modelled from cycles
  std::vector<double> transferSeconds;    // accelerator: modelled link
  std::vector<double> cycles, runs;
  std::uint64_t missing = 0, extra = 0;   // against the exact set, summed over frames
};

class Benchmark {
 public:
  using Progress = std::function<void(const std::string&)>;
  Benchmark(BenchConfig config, Progress progress);

  /// Runs every row; throws ValidationFailure when an exact method is wrong.
  nlohmann::json run();
  /// The seed-style tables as text.
  static std::string table(const nlohmann::json& results);

 private:
  nlohmann::json runRow(std::size_t objects);
  BenchConfig config_;
  Progress progress_;
};

/// Pairs of `got` not in `exact` (extra) and of `exact` not in `got` (missing); both sorted.
struct SetDifference {
  std::uint64_t missing = 0, extra = 0;
};
SetDifference compareSorted(const std::vector<Pair>& got, const std::vector<Pair>& exact);

class ValidationFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace bpaccel
