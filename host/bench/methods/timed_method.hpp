#pragma once
// One interface for every broad phase the benchmark times: Bullet's, the
// peers', the accelerator's and the cpu backend's. The benchmark's one
// timing-and-validation loop drives them all.

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "model/timeline.hpp"
#include "core/types.hpp"

namespace bpaccel {

/// What a method is, which decides how its answer is judged.
enum class MethodKind { Bullet, Peer, Accelerator, Cpu };

/// The JSON and table spelling: bullet, peer, accelerator, cpu.
std::string_view kindName(MethodKind kind);
/// Exact kinds must return exactly the exact set: any difference fails the run.
/// The others (Bullet, peers) may add pairs of padded boxes; a missing pair is
/// a finding about that library, reported in the table.
bool mustBeExact(MethodKind kind);

/// Parts of a frame whose device and link are modelled, not measured.
struct ModelledParts {
  double hostSeconds = 0;      // measured on this machine
  double partitionSeconds = 0; // measured: the part of hostSeconds that built the partition (k-d tree or grid)
  double deviceSeconds = 0;    // modelled: device cycles / clock
  double transferSeconds = 0;  // modelled: link model
  RunStats stats;              // the device's counters for the frame
  /// Modelled schedule of the same measured work with host, link and device
  /// overlapped (modelPipeline); the serial sum above is what the host runs today.
  std::shared_ptr<const FrameTimeline> pipeline;
};

/// What the table reports for one frame of a method.
struct FrameTime {
  double seconds = 0;
  std::optional<ModelledParts> parts;
};

/// A broad phase as its users keep it across frames.
class TimedMethod {
 public:
  virtual ~TimedMethod() = default;
  /// The timed work of one frame: take this frame's boxes (same count and
  /// order every frame) and find the overlapping pairs.
  virtual void update(std::span<const Aabb> boxes) = 0;
  /// The pairs of the last update (i < j, any order); not timed.
  virtual void pairs(std::vector<Pair>& out) = 0;
  /// The frame's time from the measured wall time of update(). Methods with a
  /// modelled device replace the device's simulation by its model here.
  virtual FrameTime frameTime(double measuredSeconds) const { return {measuredSeconds, std::nullopt}; }
  /// Whether the method has a paced run (runPaced).
  virtual bool hasPacedRun() const { return false; }
  /// Untimed, just before runPaced: the emulated device gets ready as a
  /// card is (its thread awake and polling for the first hand-over).
  virtual void readyPacedDevice() {}
  /// A method with a modelled device may run the last update's boxes again
  /// as its host threads would drive a real device, against a device
  /// emulated for its modelled time, and leave those pairs for pairs(); the
  /// caller times it.
  virtual void runPaced(std::span<const Aabb> /*boxes*/) {
    throw std::logic_error("this method has no paced run");
  }
};

/// What a method gets to build its structure (not timed as a frame).
struct SceneStart {
  std::span<const Aabb> boxes;  // the first frame's boxes
  float worldMin = 0;           // every box of every frame stays inside
  float worldMax = 0;           // [worldMin, worldMax] on each axis
  /// The same bounds per axis (a flat world is not a cube): inside [worldMin, worldMax].
  std::array<float, 3> worldLo{}, worldHi{};
};

/// One entry of the benchmark's line-up: how to name, skip and build a method.
struct MethodSpec {
  std::string name;
  MethodKind kind = MethodKind::Peer;
  std::string library;                  // e.g. "Bullet 3.24": the table's blocks per library
  std::optional<std::size_t> cellSize;  // accelerator and cpu: the partition's cell size
  std::string partition;                // accelerator and cpu: "k-d" or "grid"; else empty
  nlohmann::json profile;               // accelerator: the DeviceProfile it is modelled on (toJson); else null
  /// Why the method cannot run on this scene; nullopt when it can. May be empty.
  std::function<std::optional<std::string>(const SceneStart&)> skipReason;
  std::function<std::unique_ptr<TimedMethod>(const SceneStart&)> make;
};

using SkipRule = std::function<std::optional<std::string>(const SceneStart&)>;

/// The skip rule of methods that test all n(n-1)/2 pairs every frame: they
/// are skipped where that exceeds `maxTestsPerFrame`.
SkipRule allPairsSkipReason(double maxTestsPerFrame);

/// The skip rule of a sort-and-sweep along x that cannot be interrupted (set-up
/// or rebuild): skipped where the scene's pairsOverlappingOnX exceeds `maxTests`.
SkipRule sweepSkipReason(double maxTests);

}  // namespace bpaccel
