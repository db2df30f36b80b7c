#include "broad_phase_manager.hpp"

#include <algorithm>
#include <mutex>
#include <queue>

#include "../device/cpu_backend.hpp"
#include "distance_search.hpp"
#include "managed_objects.hpp"
#include "pair_finder.hpp"

namespace bpaccel {
namespace {

BroadPhaseConfig configOf(const BroadPhaseManagerOptions& o) {
  return {.cellSize = o.cellSize, .partition = o.partition, .threads = o.threads};
}

}  // namespace

template <typename S>
struct BroadPhaseManager<S>::State {
  explicit State(PairFinder f) : finder(std::move(f)) {}
  ManagedObjects<S> objects;
  PairFinder finder;
  std::mutex lock;                      // collide and distance use the scratch below
  std::vector<Pair> pairs;              // the exact overlapping pairs of the objects' AABBs ...
  std::uint64_t pairsVersion = ~0ull;   // ... as of this version of the objects
  std::vector<fcl::AABB<S>> both;       // ours then another manager's, for collide(other) and distance(other)
  std::vector<Aabb> bothBoxes;
  std::vector<Object*> theirs;

  // Ours then the other manager's objects, with their AABBs as that manager holds them (else as they are now).
  void gatherBoth(fcl::BroadPhaseCollisionManager<S>* other) {
    auto* mine = dynamic_cast<BroadPhaseManager<S>*>(other);
    other->getObjects(theirs);
    both = objects.aabbs();
    bothBoxes = objects.boxes();
    for (std::size_t k = 0; k < theirs.size(); ++k) {
      both.push_back(mine ? mine->state_->objects.aabbs()[k] : ManagedObjects<S>::checkedAabb(theirs[k], "other manager"));
      bothBoxes.push_back(mine ? mine->state_->objects.boxes()[k] : outwardBox(both.back()));
    }
  }
};

template <typename S>
BroadPhaseManager<S>::BroadPhaseManager() : BroadPhaseManager(std::make_unique<CpuBackend>()) {}

template <typename S>
BroadPhaseManager<S>::BroadPhaseManager(std::unique_ptr<Backend> backend, const BroadPhaseManagerOptions& options)
    : state_(std::make_unique<State>(PairFinder(std::move(backend), configOf(options)))) {}

template <typename S>
BroadPhaseManager<S>::BroadPhaseManager(const BackendFactory& makeBackend, const BroadPhaseManagerOptions& options)
    : state_(std::make_unique<State>(PairFinder(makeBackend, configOf(options)))) {}

template <typename S>
BroadPhaseManager<S>::~BroadPhaseManager() = default;

template <typename S>
void BroadPhaseManager<S>::registerObjects(const std::vector<Object*>& objects) {
  for (Object* o : objects) registerObject(o);
}

template <typename S>
void BroadPhaseManager<S>::registerObject(Object* object) {
  state_->objects.add(object);
}

template <typename S>
void BroadPhaseManager<S>::unregisterObject(Object* object) {
  state_->objects.remove(object);
}

template <typename S>
void BroadPhaseManager<S>::update() {
  state_->objects.readAll();
}

template <typename S>
void BroadPhaseManager<S>::update(Object* object) {
  state_->objects.readIfKnown(object);
}

template <typename S>
void BroadPhaseManager<S>::update(const std::vector<Object*>& objects) {
  for (Object* o : objects) state_->objects.readIfKnown(o);
}

template <typename S>
void BroadPhaseManager<S>::clear() {
  state_->objects.clear();
}

template <typename S>
void BroadPhaseManager<S>::getObjects(std::vector<Object*>& objects) const {
  objects = state_->objects.objects();
}

template <typename S>
std::size_t BroadPhaseManager<S>::size() const {
  return state_->objects.size();
}

template <typename S>
void BroadPhaseManager<S>::collide(void* data, fcl::CollisionCallBack<S> callback) const {
  State& s = *state_;
  const std::lock_guard guard(s.lock);
  const auto& aabbs = s.objects.aabbs();
  if (s.pairsVersion != s.objects.version()) {  // found once for any number of collide calls
    s.pairs = s.finder.find(s.objects.boxes());
    std::erase_if(s.pairs, [&](const Pair& p) { return !aabbs[p.first].overlap(aabbs[p.second]); });
    s.pairsVersion = s.objects.version();
  }
  for (const Pair& p : s.pairs)
    if (callback(s.objects.object(p.first), s.objects.object(p.second), data)) return;
}

template <typename S>
void BroadPhaseManager<S>::collide(Object* object, void* data, fcl::CollisionCallBack<S> callback) const {
  State& s = *state_;
  const std::lock_guard guard(s.lock);
  const fcl::AABB<S>& aabb = ManagedObjects<S>::checkedAabb(object, "collide");
  bool stop = false;
  s.objects.index().aabbTest(outwardBox(aabb), [&](std::uint32_t k) {
    if (!stop && s.objects.aabbs()[k].overlap(aabb)) stop = callback(s.objects.object(k), object, data);
  });
}

template <typename S>
void BroadPhaseManager<S>::collide(fcl::BroadPhaseCollisionManager<S>* other, void* data,
                                   fcl::CollisionCallBack<S> callback) const {
  if (other == this) return collide(data, callback);
  State& s = *state_;
  const std::lock_guard guard(s.lock);
  s.gatherBoth(other);
  const std::size_t split = s.objects.size();
  if (split == 0 || s.theirs.empty()) return;
  for (const Pair& p : s.finder.find(s.bothBoxes, split))
    if (s.both[p.first].overlap(s.both[p.second]) &&
        callback(s.objects.object(p.first), s.theirs[p.second - split], data))
      return;
}

template <typename S>
void BroadPhaseManager<S>::distance(void* data, fcl::DistanceCallBack<S> callback) const {
  State& s = *state_;
  const std::lock_guard guard(s.lock);
  visitByDistance<S>(s.finder, s.objects.aabbs(), 0, [&](std::uint32_t i, std::uint32_t j, S& minimum) {
    return callback(s.objects.object(i), s.objects.object(j), data, minimum);
  });
}

// Every registered object's distance to the query, then the nearest first
// while it lies below the callback's minimum.
template <typename S>
void BroadPhaseManager<S>::distance(Object* object, void* data, fcl::DistanceCallBack<S> callback) const {
  State& s = *state_;
  const std::lock_guard guard(s.lock);
  const fcl::AABB<S>& aabb = ManagedObjects<S>::checkedAabb(object, "distance");
  using Candidate = std::pair<S, std::uint32_t>;
  std::vector<Candidate> candidates(s.objects.size());
  for (std::uint32_t k = 0; k < candidates.size(); ++k) candidates[k] = {s.objects.aabbs()[k].distance(aabb), k};
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<>> nearest(std::greater<>{},
                                                                                  std::move(candidates));
  S minimum = std::numeric_limits<S>::max();
  for (; !nearest.empty() && nearest.top().first < minimum; nearest.pop())
    if (callback(s.objects.object(nearest.top().second), object, data, minimum)) return;
}

template <typename S>
void BroadPhaseManager<S>::distance(fcl::BroadPhaseCollisionManager<S>* other, void* data,
                                    fcl::DistanceCallBack<S> callback) const {
  if (other == this) return distance(data, callback);
  State& s = *state_;
  const std::lock_guard guard(s.lock);
  s.gatherBoth(other);
  const std::size_t split = s.objects.size();
  if (split == 0 || s.theirs.empty()) return;
  visitByDistance<S>(s.finder, s.both, split, [&](std::uint32_t i, std::uint32_t j, S& minimum) {
    return callback(s.objects.object(i), s.theirs[j - split], data, minimum);
  });
}

template class BroadPhaseManager<float>;
template class BroadPhaseManager<double>;

}  // namespace bpaccel
