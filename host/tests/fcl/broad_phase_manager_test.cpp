// bpaccel::BroadPhaseManager against FCL's own DynamicAABBTreeCollisionManager,
// as FCL's broad-phase tests compare managers: the same pairs through the same
// callbacks (self, with an object, with another manager) after every kind of
// update, no pair twice, the callback's early stop, for float and double; and
// the same contacts and the same minimum distance with FCL's default callbacks.
// Those two run on double only: libfcl ships its narrow phase compiled for
// double, so a float run would compile all of FCL's GJK and EPA into this test
// (two minutes, fourteen under the sanitizers) to test FCL's code, not ours.

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/broadphase/default_broadphase_callbacks.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <gtest/gtest.h>

#include "device/built_device.hpp"
#include "dropping_backend.hpp"
#include "device/model_backend.hpp"
#include "fcl/broad_phase_manager.hpp"

namespace {

template <typename S>
using Object = fcl::CollisionObject<S>;
template <typename S>
using Objects = std::vector<std::unique_ptr<Object<S>>>;
template <typename S>
using PairSet = std::set<std::pair<const Object<S>*, const Object<S>*>>;

// n shapes (boxes, spheres, cylinders, capsules) of size about 2 to 12,
// rotated and placed at random in [-scale, scale]^3.
template <typename S>
Objects<S> environment(std::size_t n, S scale, unsigned seed) {
  std::mt19937 rng(seed);
  auto uni = [&](S lo, S hi) { return std::uniform_real_distribution<S>(lo, hi)(rng); };
  Objects<S> env;
  for (std::size_t i = 0; i < n; ++i) {
    std::shared_ptr<fcl::CollisionGeometry<S>> shape;
    switch (i % 4) {
      case 0: shape = std::make_shared<fcl::Box<S>>(uni(1, 12), uni(1, 6), uni(2, 12)); break;
      case 1: shape = std::make_shared<fcl::Sphere<S>>(uni(1, 6)); break;
      case 2: shape = std::make_shared<fcl::Cylinder<S>>(uni(1, 4), uni(2, 12)); break;
      default: shape = std::make_shared<fcl::Capsule<S>>(uni(1, 3), uni(2, 10)); break;
    }
    fcl::Transform3<S> tf = fcl::Transform3<S>::Identity();
    tf.translation() = fcl::Vector3<S>(uni(-scale, scale), uni(-scale, scale), uni(-scale, scale));
    tf.linear() = fcl::AngleAxis<S>(uni(0, 3), fcl::Vector3<S>(uni(-1, 1), uni(-1, 1), uni(-1, 1)).normalized())
                      .toRotationMatrix();
    env.push_back(std::make_unique<Object<S>>(shape, tf));
  }
  return env;
}

template <typename S>
std::vector<Object<S>*> raw(const Objects<S>& env) {
  std::vector<Object<S>*> r;
  for (const auto& o : env) r.push_back(o.get());
  return r;
}

// Moves every object a little, as FCL's update test does.
template <typename S>
void jiggle(const Objects<S>& env, S step, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<S> d(-step, step);
  for (const auto& o : env) {
    o->setTranslation(o->getTranslation() + fcl::Vector3<S>(d(rng), d(rng), d(rng)));
    o->computeAABB();
  }
}

template <typename S>
struct Recorder {
  PairSet<S> pairs;
  std::size_t calls = 0, stopAfter = ~std::size_t{0};
  bool duplicate = false;
};

template <typename S>
bool record(Object<S>* a, Object<S>* b, void* data) {
  auto& r = *static_cast<Recorder<S>*>(data);
  r.duplicate |= !r.pairs.emplace(std::min<const Object<S>*>(a, b), std::max<const Object<S>*>(a, b)).second;
  return ++r.calls >= r.stopAfter;
}

// (registered object, query) as the managers order them.
template <typename S>
bool recordOrdered(Object<S>* a, Object<S>* b, void* data) {
  auto& r = *static_cast<Recorder<S>*>(data);
  r.duplicate |= !r.pairs.emplace(a, b).second;
  return ++r.calls >= r.stopAfter;
}

template <typename S>
Recorder<S> selfPairs(const fcl::BroadPhaseCollisionManager<S>& m, std::size_t stopAfter = ~std::size_t{0}) {
  Recorder<S> r;
  r.stopAfter = stopAfter;
  m.collide(&r, record<S>);
  return r;
}

// Two sets of objects, each in FCL's tree and in ours, set up.
template <typename S>
struct TwoScenes {
  Objects<S> env, others;
  fcl::DynamicAABBTreeCollisionManager<S> theirs, theirsOthers;
  bpaccel::BroadPhaseManager<S> mine, mineOthers;

  TwoScenes(Objects<S> first, Objects<S> second) : env(std::move(first)), others(std::move(second)) {
    for (auto* m : std::initializer_list<fcl::BroadPhaseCollisionManager<S>*>{&theirs, &mine})
      m->registerObjects(raw(env));
    for (auto* m : std::initializer_list<fcl::BroadPhaseCollisionManager<S>*>{&theirsOthers, &mineOthers})
      m->registerObjects(raw(others));
    for (auto* m : std::initializer_list<fcl::BroadPhaseCollisionManager<S>*>{&theirs, &mine, &theirsOthers, &mineOthers})
      m->setup();
  }
};

template <typename S>
class BroadPhaseManagerTest : public ::testing::Test {};
using Scalars = ::testing::Types<float, double>;
TYPED_TEST_SUITE(BroadPhaseManagerTest, Scalars);

TYPED_TEST(BroadPhaseManagerTest, SamePairsAsFclTreeAfterEveryKindOfUpdate) {
  using S = TypeParam;
  for (const std::size_t n : {1u, 2u, 50u, 1500u}) {
    auto env = environment<S>(n, 60, static_cast<unsigned>(n));
    fcl::DynamicAABBTreeCollisionManager<S> theirs;
    bpaccel::BroadPhaseManager<S> mine;
    theirs.registerObjects(raw(env));
    mine.registerObjects(raw(env));
    theirs.setup();
    mine.setup();
    EXPECT_EQ(mine.size(), n);
    for (int round = 0; round < 4; ++round) {
      const auto want = selfPairs(theirs);
      const auto got = selfPairs(mine);
      EXPECT_FALSE(got.duplicate) << "n=" << n << " round " << round;
      ASSERT_EQ(got.pairs, want.pairs) << "n=" << n << " round " << round;
      if (n == 1500) EXPECT_GT(want.pairs.size(), 300u);
      for (std::size_t q = 0; q < std::min<std::size_t>(n, 20); ++q) {  // the query tree after each update
        Recorder<S> wantQ, gotQ;
        theirs.collide(env[q].get(), &wantQ, recordOrdered<S>);
        mine.collide(env[q].get(), &gotQ, recordOrdered<S>);
        ASSERT_EQ(gotQ.pairs, wantQ.pairs) << "n=" << n << " round " << round << " query " << q;
      }
      jiggle(env, S(3), static_cast<unsigned>(round));
      switch (round) {  // all objects at once, one by one, as a list
        case 0: theirs.update(); mine.update(); break;
        case 1: for (auto* o : raw(env)) { theirs.update(o); mine.update(o); } break;
        default: theirs.update(raw(env)); mine.update(raw(env)); break;
      }
    }
  }
}

TYPED_TEST(BroadPhaseManagerTest, QueriesAndOtherManagersGiveFclsPairs) {
  using S = TypeParam;
  TwoScenes<S> scenes(environment<S>(800, 50, 3), environment<S>(300, 50, 4));
  auto &theirs = scenes.theirs, &theirsMore = scenes.theirsOthers;
  auto &mine = scenes.mine, &mineMore = scenes.mineOthers;
  auto queries = environment<S>(100, 55, 5);
  std::size_t hits = 0;
  for (const auto& q : queries) {
    Recorder<S> want, got;
    theirs.collide(q.get(), &want, recordOrdered<S>);
    mine.collide(q.get(), &got, recordOrdered<S>);
    ASSERT_EQ(got.pairs, want.pairs);
    hits += want.pairs.size();
  }
  EXPECT_GT(hits, 20u);
  Recorder<S> want, got;
  theirs.collide(&theirsMore, &want, recordOrdered<S>);
  mine.collide(&mineMore, &got, recordOrdered<S>);
  EXPECT_EQ(got.pairs, want.pairs);
  EXPECT_GT(want.pairs.size(), 50u);
  Recorder<S> fromFcl;  // another kind of manager: its objects and AABBs
  mine.collide(&theirsMore, &fromFcl, recordOrdered<S>);
  EXPECT_EQ(fromFcl.pairs, want.pairs);
  EXPECT_EQ(selfPairs(mine).pairs, [&] {
    Recorder<S> self;
    mine.collide(&mine, &self, record<S>);
    return self.pairs;
  }());
}

// The callback's true stops the search at once, as in FCL.
TYPED_TEST(BroadPhaseManagerTest, CallbackStopsTheSearch) {
  using S = TypeParam;
  auto env = environment<S>(600, 40, 6), queries = environment<S>(20, 40, 7);
  bpaccel::BroadPhaseManager<S> mine, other;
  mine.registerObjects(raw(env));
  other.registerObjects(raw(queries));
  ASSERT_GT(selfPairs(mine).pairs.size(), 20u);
  for (const std::size_t stop : {1u, 7u}) {
    EXPECT_EQ(selfPairs(mine, stop).calls, stop);
    Recorder<S> r;
    r.stopAfter = stop;
    mine.collide(&other, &r, recordOrdered<S>);
    EXPECT_EQ(r.calls, stop);
  }
}

// FCL's own test: DefaultCollisionFunction with 1, 10 and unlimited contacts
// finds as many contacts as FCL's tree, self and per query object.
TEST(BroadPhaseManagerDefaultCallbacks, SameContactsAsFclTree) {
  using S = double;
  auto env = environment<S>(400, 35, 8), queries = environment<S>(40, 35, 9);
  fcl::DynamicAABBTreeCollisionManager<S> theirs;
  bpaccel::BroadPhaseManager<S> mine;
  theirs.registerObjects(raw(env));
  mine.registerObjects(raw(env));
  theirs.setup();
  for (const std::size_t contacts : {1u, 10u, 100000u}) {
    fcl::DefaultCollisionData<S> want, got;
    want.request.num_max_contacts = got.request.num_max_contacts = contacts;
    theirs.collide(&want, fcl::DefaultCollisionFunction<S>);
    mine.collide(&got, fcl::DefaultCollisionFunction<S>);
    EXPECT_EQ(got.result.numContacts(), want.result.numContacts()) << contacts;
    if (contacts == 100000u) EXPECT_GT(want.result.numContacts(), 20u);
    for (const auto& q : queries) {
      fcl::DefaultCollisionData<S> qw, qg;
      qw.request.num_max_contacts = qg.request.num_max_contacts = contacts;
      theirs.collide(q.get(), &qw, fcl::DefaultCollisionFunction<S>);
      mine.collide(q.get(), &qg, fcl::DefaultCollisionFunction<S>);
      EXPECT_EQ(qg.result.numContacts(), qw.result.numContacts()) << contacts;
    }
  }
}

// FCL's distance test: the same minimum distance with DefaultDistanceFunction,
// self, to query objects that collide with nothing, and to another manager.
TEST(BroadPhaseManagerDefaultCallbacks, SameMinimumDistanceAsFclTree) {
  using S = double;
  const S tolerance = S(1e-6);
  // Sparse enough that the minima are gaps, not the -1 FCL gives for overlapping shapes.
  TwoScenes<S> scenes(environment<S>(150, 400, 10), environment<S>(40, 400, 11));
  auto &theirs = scenes.theirs, &theirsOthers = scenes.theirsOthers;
  auto &mine = scenes.mine, &mineOthers = scenes.mineOthers;
  auto queries = environment<S>(30, 400, 12);
  auto same = [&](S want, S got) { EXPECT_NEAR(got, want, tolerance * std::max(S(1), std::fabs(want))); };
  {
    fcl::DefaultDistanceData<S> want, got;
    theirs.distance(&want, fcl::DefaultDistanceFunction<S>);
    mine.distance(&got, fcl::DefaultDistanceFunction<S>);
    same(want.result.min_distance, got.result.min_distance);
    EXPECT_GT(want.result.min_distance, S(0)) << "the scene should leave gaps to measure";
  }
  for (const auto& q : queries) {
    fcl::DefaultDistanceData<S> want, got;
    theirs.distance(q.get(), &want, fcl::DefaultDistanceFunction<S>);
    mine.distance(q.get(), &got, fcl::DefaultDistanceFunction<S>);
    same(want.result.min_distance, got.result.min_distance);
  }
  fcl::DefaultDistanceData<S> want, got;
  theirs.distance(&theirsOthers, &want, fcl::DefaultDistanceFunction<S>);
  mine.distance(&mineOthers, &got, fcl::DefaultDistanceFunction<S>);
  same(want.result.min_distance, got.result.min_distance);
  EXPECT_GT(want.result.min_distance, S(0)) << "the scene should leave gaps to measure";
}

// The contract behind distance: every pair closer than the final minimum
// reaches the callback, nearest first, and none at or beyond it.
TYPED_TEST(BroadPhaseManagerTest, DistanceVisitsEveryPairBelowTheMinimum) {
  using S = TypeParam;
  auto env = environment<S>(200, 120, 13);
  bpaccel::BroadPhaseManager<S> mine;
  mine.registerObjects(raw(env));
  struct Seen {
    std::vector<S> distances;  // each visited pair's AABB distance, in order
    S stopAt = 0;
  } seen;
  seen.stopAt = S(4);  // the callback's own "distance": at least this, or the AABBs' distance
  mine.distance(&seen, [](Object<S>* a, Object<S>* b, void* data, S& minimum) {
    auto& s = *static_cast<Seen*>(data);
    const S d = a->getAABB().distance(b->getAABB());
    s.distances.push_back(d);
    minimum = std::min(minimum, std::max(d, s.stopAt));
    return false;
  });
  ASSERT_FALSE(seen.distances.empty());
  EXPECT_TRUE(std::is_sorted(seen.distances.begin(), seen.distances.end()));
  std::size_t below = 0;
  for (std::size_t i = 0; i < env.size(); ++i)
    for (std::size_t j = i + 1; j < env.size(); ++j) below += env[i]->getAABB().distance(env[j]->getAABB()) < seen.stopAt;
  const auto visitedBelow = static_cast<std::size_t>(
      std::count_if(seen.distances.begin(), seen.distances.end(), [&](S d) { return d < seen.stopAt; }));
  EXPECT_EQ(visitedBelow, below);
}

TYPED_TEST(BroadPhaseManagerTest, RegistryKeepsFclsBookkeeping) {
  using S = TypeParam;
  auto env = environment<S>(10, 10, 14);
  bpaccel::BroadPhaseManager<S> mine;
  EXPECT_TRUE(mine.empty());
  mine.registerObjects(raw(env));
  mine.update();  // leaves the query tree to be rebuilt: the removal must reach it too
  mine.unregisterObject(env[3].get());
  Recorder<S> near3;
  mine.collide(env[3].get(), &near3, recordOrdered<S>);
  EXPECT_EQ(near3.pairs.count({env[3].get(), env[3].get()}), 0u) << "an unregistered object still reported";
  std::vector<Object<S>*> objects;
  mine.getObjects(objects);
  EXPECT_EQ(objects.size(), 9u);
  EXPECT_EQ(std::count(objects.begin(), objects.end(), env[3].get()), 0);
  for (const auto& pr : selfPairs(mine).pairs) EXPECT_TRUE(pr.first != env[3].get() && pr.second != env[3].get());
  EXPECT_THROW(mine.unregisterObject(env[3].get()), std::invalid_argument);
  EXPECT_THROW(mine.registerObject(env[4].get()), std::invalid_argument);
  mine.update(env[3].get());  // not registered: nothing, as in FCL
  mine.clear();
  EXPECT_TRUE(mine.empty());
  EXPECT_TRUE(selfPairs(mine).pairs.empty());
}

TYPED_TEST(BroadPhaseManagerTest, RefusesAnAabbWithNanNamingTheObject) {
  using S = TypeParam;
  auto env = environment<S>(4, 10, 15);
  bpaccel::BroadPhaseManager<S> mine;
  mine.registerObjects(raw(env));
  env[2]->setTranslation(fcl::Vector3<S>(std::nan(""), 0, 0));
  env[2]->computeAABB();
  try {
    mine.update();
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("has NaN in its AABB on axis 0"), std::string::npos) << e.what();
  }
  EXPECT_THROW(mine.collide(env[2].get(), nullptr, record<S>), std::invalid_argument);
  EXPECT_EQ(mine.size(), 4u);
}

// An object whose AABB was never computed (FCL's empty AABB, min above max).
template <typename S>
struct UncomputedObject : Object<S> {
  explicit UncomputedObject(std::shared_ptr<fcl::CollisionGeometry<S>> shape) : Object<S>(shape) {
    this->aabb = fcl::AABB<S>();
  }
};

TYPED_TEST(BroadPhaseManagerTest, RefusesAnAabbWithMinAboveMaxBeforeRegistering) {
  using S = TypeParam;
  UncomputedObject<S> empty(std::make_shared<fcl::Sphere<S>>(1));
  bpaccel::BroadPhaseManager<S> mine;
  try {
    mine.registerObject(&empty);
    FAIL() << "an inverted AABB accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("min above its max on axis 0"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(mine.empty());
}

// Any backend: the cycle-exact model of the device gives the same pairs.
TEST(BroadPhaseManager, RunsOnTheModelledDevice) {
  auto env = environment<double>(700, 40, 16);
  fcl::DynamicAABBTreeCollisionManager<double> theirs;
  bpaccel::BroadPhaseManager<double> onDevice(std::make_unique<bpaccel::ModelBackend>(bpaccel::builtDeviceParams()));
  theirs.registerObjects(raw(env));
  onDevice.registerObjects(raw(env));
  theirs.setup();
  EXPECT_EQ(selfPairs(onDevice).pairs, selfPairs(theirs).pairs);
  // The comparison catches a backend that loses pairs.
  bpaccel::BroadPhaseManager<double> losing(std::make_unique<bpaccel::testing::DroppingBackend>());
  losing.registerObjects(raw(env));
  EXPECT_LT(selfPairs(losing).pairs.size(), selfPairs(theirs).pairs.size());
}

}  // namespace
