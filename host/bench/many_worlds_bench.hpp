#pragma once
// Many small worlds a frame, as batched learning and simulation step them:
// W worlds of n boxes each, every box moving, and each world's pairs found by
// the cpu backend through ManyWorlds, by a peer kept per world (FCL's tree,
// btDbvtBroadphase), and by the accelerator through ManyWorlds (host measured,
// device and link modelled per profile). Every world's pairs are validated.

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/types.hpp"
#include "methods/accelerator_method.hpp"
#include "model/device_profile.hpp"
#include "scenes/scene.hpp"

namespace bpaccel {

/// W worlds, each a cube of the bench's density holding n boxes of its sizes
/// and speeds that turn about one axis, move and bounce off the cube's walls
/// (kinematic: boxes pass through each other, so no physics engine is needed
/// for 4096 worlds; every frame is validated, so none is needed to be fair).
class BouncingWorlds {
 public:
  BouncingWorlds(std::size_t worlds, std::size_t boxesPerWorld, const SceneConfig& cube);
  void step();
  std::size_t worlds() const { return boxes_.size() / perWorld_; }
  /// World w's boxes this frame.
  std::span<const Aabb> world(std::size_t w) const { return {boxes_.data() + w * perWorld_, perWorld_}; }
  float edge() const { return edge_; }

 private:
  struct Body {
    std::array<float, 3> centre, velocity, half;
    int spinAxis = 0;
    float angle = 0, spin = 0, reach = 0;  // reach: the half diagonal, so a turned box stays inside
  };
  void boxOf(const Body& b, Aabb& out) const;
  std::size_t perWorld_;
  float edge_, timeStep_;
  std::vector<Body> bodies_;
  std::vector<Aabb> boxes_;
};

struct ManyWorldsBenchConfig {
  std::size_t worlds = 0;  // 0: no table
  std::vector<std::size_t> boxesPerWorld{16, 32, 64};
  std::size_t frames = 5, warmup = 1;
  SceneConfig scene;  // sizes, density, speeds, time step and seed of each world
  /// The accelerator's device (none: no accelerator rows) and the profiles
  /// its one measured run is modelled on (none: the device's own clock and link).
  std::shared_ptr<const DeviceConfig> device;
  std::vector<DeviceProfile> profiles;
};

/// A way to find every world's pairs, kept across frames.
class WorldsMethod {
 public:
  virtual ~WorldsMethod() = default;
  virtual void update(std::span<const std::span<const Aabb>> worlds) = 0;
  /// World w's pairs of the last update (i < j, any order, maybe repeated).
  virtual void pairs(std::size_t w, std::vector<Pair>& out) = 0;
  /// A device method's counters and the wall time spent simulating its
  /// device in the last update (not host work); none for the others.
  virtual const RunStats* deviceStats() const { return nullptr; }
  virtual double deviceSimulationSeconds() const { return 0; }
};

struct WorldsMethodSpec {
  std::string name;
  MethodKind kind = MethodKind::Peer;
  std::string library;
  /// Why it cannot run worlds of this many boxes; null or nullopt when it can.
  std::function<std::optional<std::string>(std::size_t boxesPerWorld)> skipReason;
  std::function<std::unique_ptr<WorldsMethod>(std::span<const std::span<const Aabb>> first, float edge)> make;
};

/// The cpu backend through ManyWorlds, btDbvtBroadphase and FCL's tree (in
/// each usage of fclMethods) one per world, and the accelerator with `device`.
std::vector<WorldsMethodSpec> manyWorldsLineUp(const std::shared_ptr<const DeviceConfig>& device);

/// One row per world size; throws ValidationFailure (naming the world) when
/// an exact method's pairs of any world differ from the exact set.
nlohmann::json runManyWorldsBench(const ManyWorldsBenchConfig& config, const std::vector<WorldsMethodSpec>& lineUp,
                                  const std::function<void(const std::string&)>& progress);
std::string manyWorldsTable(const nlohmann::json& manyWorlds);

}  // namespace bpaccel
