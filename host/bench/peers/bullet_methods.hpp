#pragma once
// Bullet's own broad phases, kept across frames as Bullet users keep them.

#include <memory>
#include <span>
#include <string>
#include <vector>

#include "methods/timed_method.hpp"
#include "core/types.hpp"

class btBroadphaseInterface;
class btBroadphaseProxy;
class btCollisionDispatcher;
class btDefaultCollisionConfiguration;

namespace bpaccel {

class BulletMethod final : public TimedMethod {
 public:
  enum class Kind { Dbvt, AxisSweep32, Simple };
  static std::string name(Kind kind);

  /// Creates one proxy per box. `worldMin`/`worldMax` bound the sweep-and-prune's quantisation.
  /// With `shared`, its pairs go through that dispatcher (which must outlive
  /// it), as many small worlds share one; else through a dispatcher of its own.
  BulletMethod(Kind kind, std::span<const Aabb> initial, float worldMin, float worldMax,
               btCollisionDispatcher* shared = nullptr);
  ~BulletMethod() override;
  BulletMethod(const BulletMethod&) = delete;
  BulletMethod& operator=(const BulletMethod&) = delete;

  /// setAabb for every object and calculateOverlappingPairs: the work timed per frame.
  void update(std::span<const Aabb> boxes) override;
  /// The pairs in the broad phase's pair cache (i < j, unsorted).
  void pairs(std::vector<Pair>& out) override;
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
  std::unique_ptr<btDefaultCollisionConfiguration> config_;
  std::unique_ptr<btCollisionDispatcher> ownDispatcher_;
  btCollisionDispatcher* dispatcher_;  // ownDispatcher_ or a shared one
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::vector<btBroadphaseProxy*> proxies_;  // index = object
};

/// Bullet's three broad phases for the benchmark. btSimpleBroadphase tests
/// all pairs every frame: it is skipped above `maxAllPairsTests` pair tests a frame.
std::vector<MethodSpec> bulletMethods(double maxAllPairsTests);

/// Why bt32BitAxisSweep3 cannot run at `objects`, if it cannot: Bullet inserts
/// each proxy by insertion sort on every axis, so its set-up is Theta(n^2).
std::optional<std::string> axisSweepSkipReason(std::size_t objects);

}  // namespace bpaccel
