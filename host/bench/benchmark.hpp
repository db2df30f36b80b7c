#pragma once
// The bouncing-cube benchmark: every broad phase behind TimedMethod, timed
// and validated by one loop, frame after frame, on the same scene.

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "methods/accelerator_method.hpp"
#include "many_worlds_bench.hpp"
#include "methods/binning_method.hpp"
#include "query_bench.hpp"
#include "scenes/scene.hpp"
#include "scenes/scene_families.hpp"
#include "methods/timed_method.hpp"
#include "core/types.hpp"

namespace bpaccel {

struct BenchConfig {
  std::vector<std::size_t> objectCounts{100, 1000, 8000};
  /// Each family runs every object count, one row each (scene_families.hpp).
  std::vector<SceneFamily> families{SceneFamily::Cube};
  std::size_t frames = 50;  // timed frames per row
  std::size_t warmup = 5;   // frames simulated and run but not timed
  SceneConfig scene;        // objects is set per row
  /// A method whose set-up or one frame's update takes longer is stopped for
  /// the rest of the row and listed as skipped with the time it took.
  double maxMethodSeconds = 60;
  /// Whole-step comparison (full stepSimulation of the world with Bullet's
  /// btDbvtBroadphase and with bpaccel::BulletDropIn on the cpu backend) at
  /// this object count; 0: none.
  std::size_t wholeStepObjects = 0;
  std::size_t wholeStepFrames = 20;
  /// Broad-phase ray tests cast after each timed whole step (0: none).
  std::size_t wholeStepRays = 0;
  /// Ray and box queries (query_bench.hpp) at these object counts; empty: none.
  QueryBenchConfig queries;
  /// Many small worlds (many_worlds_bench.hpp; its scene is set from `scene`); worlds 0: none.
  ManyWorldsBenchConfig manyWorlds;
};

/// What the standard line-up holds.
struct LineUpConfig {
  std::vector<std::optional<std::size_t>> cellSizes{std::nullopt, 16, 32, 64, 128, 256};
  /// Cell sizes of the extra "accelerator grid C" and "cpu grid C" rows (the
  /// uniform grid partition instead of the k-d tree); empty: none.
  std::vector<std::size_t> gridCellSizes{64, 128, 256};
  /// Methods that test all n(n-1)/2 pairs a frame are skipped above this.
  double maxAllPairsTests = 1e8;
  /// A sweep along x that cannot be stopped midway (FCL's SaP, rebuilt every
  /// frame, and ODE's sweep-and-prune space) is skipped where more pairs than
  /// this overlap on x.
  double maxSweepTests = 1e9;
  std::shared_ptr<const DeviceConfig> device;  // the accelerator's; none: no accelerator methods
  /// The platforms the accelerator is modelled on: its rows once per profile,
  /// each on that profile's clock and link (withProfile) and named by it.
  /// Empty: once, on the device's own clock and link.
  std::vector<DeviceProfile> profiles;
  /// Above 1: the cpu backend also runs on this many threads, per cell size with a tree.
  std::size_t cpuThreads = 0;
};

/// Bullet's three broad phases, the peers (FCL, CGAL, ODE), then the
/// accelerator (per profile) and the cpu backend per cell size.
std::vector<MethodSpec> standardLineUp(const LineUpConfig& config);
/// The line-up's settings for the JSON's configuration.
nlohmann::json describe(const LineUpConfig& config);

class Benchmark {
 public:
  using Progress = std::function<void(const std::string&)>;
  /// `configuration` describes the line-up (see describe) and goes into the JSON.
  Benchmark(BenchConfig config, std::vector<MethodSpec> lineUp, nlohmann::json configuration, Progress progress);

  /// Runs every row; throws ValidationFailure when an exact method is wrong.
  nlohmann::json run();
  /// The tables as text.
  static std::string table(const nlohmann::json& results);

 private:
  nlohmann::json runRow(SceneFamily family, std::size_t objects);
  nlohmann::json wholeSteps();
  BenchConfig config_;
  std::vector<MethodSpec> lineUp_;
  nlohmann::json configuration_;
  Progress progress_;
};

/// Samples `v` times `scale`: median, min, max, and the medians of the first
/// and of the last tenth (at least one sample each), in order; null when empty.
nlohmann::json summary(const std::vector<double>& v, double scale);

/// Pairs of `got` not in `exact` (extra) and of `exact` not in `got` (missing); both sorted.
struct SetDifference {
  std::uint64_t missing = 0, extra = 0;
};
SetDifference compareSorted(const std::vector<Pair>& got, const std::vector<Pair>& exact);

/// An exact method's pair set differed from the exact set.
class ValidationFailure : public std::runtime_error {
 public:
  ValidationFailure(std::string method, std::size_t objects, std::size_t frame, SetDifference difference,
                    std::size_t exactPairs);
  const std::string& method() const { return method_; }
  const SetDifference& difference() const { return difference_; }

 private:
  std::string method_;
  SetDifference difference_;
};

}  // namespace bpaccel
