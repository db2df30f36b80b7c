#pragma once
// bpaccel::BroadPhaseManager: an fcl::BroadPhaseCollisionManager that code
// written for FCL's managers takes in their place, finding pairs with
// BroadPhase on any backend.

#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include <fcl/broadphase/broadphase_collision_manager.h>

#include "../device/backend.hpp"
#include "../partition/partition.hpp"

namespace bpaccel {

struct BroadPhaseManagerOptions {
  /// The partition's cell size (none: the scene is one cell, chunked to the backend's capacity).
  std::optional<std::size_t> cellSize = 64;
  PartitionKind partition = PartitionKind::UniformGrid;
  /// Threads sharing the cells; more than one needs a backend factory.
  std::size_t threads = 1;
};

/// FCL's manager contract on BroadPhase. What it reports is what FCL's
/// DynamicAABBTreeCollisionManager reports:
/// - collide(): every pair of registered objects whose AABBs (as the last
///   registerObject/update read them from getAABB()) overlap, touching
///   included (fcl::AABB::overlap), each once, until the callback returns
///   true; collide(obj): each registered object whose AABB overlaps obj's
///   current one, as callback(registered, obj); collide(other): each
///   pair (ours, theirs) whose AABBs overlap;
/// - distance(): the callback is called on pairs in ascending order of their
///   AABBs' distance (fcl::AABB::distance) for as long as that distance lies
///   below the distance the callback last returned, so the callback's minimum
///   is the true one (FCL's own managers' contract).
/// The pairs come from float boxes rounded outward from the AABBs (any S) and
/// are checked with fcl::AABB::overlap in S before the callback sees them.
///
/// Unlike FCL's managers: registering an object twice, or unregistering one
/// that is not registered, throws std::invalid_argument; an AABB with NaN or
/// min above max throws std::invalid_argument naming the object when it is
/// read. update(obj) of an object not registered does nothing, as in FCL. collide and distance
/// keep scratch state: calls on one manager are serialised (a lock), and a
/// callback must not call its own manager's collide or distance.
template <typename S>
class BroadPhaseManager final : public fcl::BroadPhaseCollisionManager<S> {
 public:
  using Object = fcl::CollisionObject<S>;
  /// On the cpu backend.
  BroadPhaseManager();
  explicit BroadPhaseManager(std::unique_ptr<Backend> backend, const BroadPhaseManagerOptions& options = {});
  /// options.threads workers, each with a backend of its own from `makeBackend`.
  explicit BroadPhaseManager(const BackendFactory& makeBackend, const BroadPhaseManagerOptions& options = {});
  ~BroadPhaseManager() override;
  BroadPhaseManager(const BroadPhaseManager&) = delete;
  BroadPhaseManager& operator=(const BroadPhaseManager&) = delete;

  void registerObjects(const std::vector<Object*>& objects) override;
  void registerObject(Object* object) override;
  void unregisterObject(Object* object) override;
  /// Nothing to prepare: pairs are found when asked for.
  void setup() override {}
  /// Reads every object's AABB again.
  void update() override;
  void update(Object* object) override;
  void update(const std::vector<Object*>& objects) override;
  void clear() override;
  /// In registration order (an unregistered object's place goes to the last one).
  void getObjects(std::vector<Object*>& objects) const override;
  void collide(Object* object, void* data, fcl::CollisionCallBack<S> callback) const override;
  void distance(Object* object, void* data, fcl::DistanceCallBack<S> callback) const override;
  void collide(void* data, fcl::CollisionCallBack<S> callback) const override;
  void distance(void* data, fcl::DistanceCallBack<S> callback) const override;
  void collide(fcl::BroadPhaseCollisionManager<S>* other, void* data, fcl::CollisionCallBack<S> callback) const override;
  void distance(fcl::BroadPhaseCollisionManager<S>* other, void* data, fcl::DistanceCallBack<S> callback) const override;
  bool empty() const override { return size() == 0; }
  std::size_t size() const override;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

using BroadPhaseManagerf = BroadPhaseManager<float>;
using BroadPhaseManagerd = BroadPhaseManager<double>;

extern template class BroadPhaseManager<float>;
extern template class BroadPhaseManager<double>;

}  // namespace bpaccel
