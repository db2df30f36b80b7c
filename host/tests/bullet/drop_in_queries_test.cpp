// bpaccel::BulletDropIn's rayTest and aabbTest: the proxies btDbvtBroadphase
// reports on the same exact boxes, Bullet's own tests (btRayAabb2,
// TestAabbAgainstAabb2) proxy by proxy after moves, creations and removals,
// and a callback that shortens the ray.

#include <algorithm>
#include <array>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <LinearMath/btAabbUtil2.h>
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include "bullet/bullet_drop_in.hpp"
#include "device/cpu_backend.hpp"
#include "query/ray.hpp"
#include "scenes.hpp"

namespace {

using bpaccel::Aabb;
using bpaccel::BulletDropIn;
using Ids = std::vector<int>;

btVector3 vec(const std::array<float, 3>& v) { return {v[0], v[1], v[2]}; }

// The proxies a callback was given, by id (the client object).
struct Kept {
  void keep(const btBroadphaseProxy* proxy) {
    ids.push_back(static_cast<int>(reinterpret_cast<std::intptr_t>(proxy->m_clientObject)));
  }
  Ids sorted() const {
    Ids s = ids;
    std::sort(s.begin(), s.end());
    return s;
  }
  Ids ids;
};

// A ray callback with the fields btCollisionWorld::rayTest gives its own
// (RayQuery::segment builds them the same way).
struct Collect final : btBroadphaseRayCallback, Kept {
  explicit Collect(const bpaccel::RayQuery& ray) { bpaccel::aimRay(*this, ray); }
  bool process(const btBroadphaseProxy* proxy) override {
    keep(proxy);
    return true;
  }
};

struct CollectBox final : btBroadphaseAabbCallback, Kept {
  bool process(const btBroadphaseProxy* proxy) override {
    keep(proxy);
    return true;
  }
};

// Both broad phases over the same proxies; client object = the box's id.
struct TwoBroadPhases {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase dbvt;
  BulletDropIn mine{std::make_unique<bpaccel::CpuBackend>()};
  std::vector<btBroadphaseProxy*> dbvtProxies, myProxies;  // by id; null once destroyed

  // btDbvtBroadphase frees a proxy only in destroyProxy, as a Bullet world does when it removes an object.
  ~TwoBroadPhases() {
    for (std::size_t id = 0; id < myProxies.size(); ++id) {
      if (dbvtProxies[id]) dbvt.destroyProxy(dbvtProxies[id], &dispatcher);
      if (myProxies[id]) mine.destroyProxy(myProxies[id], &dispatcher);
    }
  }

  void add(int id, const Aabb& b) {
    if (static_cast<std::size_t>(id) >= myProxies.size()) {
      dbvtProxies.resize(static_cast<std::size_t>(id) + 1, nullptr);
      myProxies.resize(static_cast<std::size_t>(id) + 1, nullptr);
    }
    void* client = reinterpret_cast<void*>(static_cast<std::intptr_t>(id));
    dbvtProxies[static_cast<std::size_t>(id)] =
        dbvt.createProxy(vec(b.min), vec(b.max), BOX_SHAPE_PROXYTYPE, client, 1, -1, &dispatcher);
    myProxies[static_cast<std::size_t>(id)] =
        mine.createProxy(vec(b.min), vec(b.max), BOX_SHAPE_PROXYTYPE, client, 1, -1, &dispatcher);
  }
  // The live proxies Bullet's own tests accept, from the drop-in's AABBs.
  Ids bulletRay(const btVector3& from, const Collect& cb, const btVector3& growMin, const btVector3& growMax) {
    Ids ids;
    for (std::size_t id = 0; id < myProxies.size(); ++id) {
      if (!myProxies[id]) continue;
      btVector3 lo, hi;
      mine.getAabb(myProxies[id], lo, hi);
      const btVector3 bounds[2] = {lo - growMax, hi - growMin};
      btScalar tmin;
      if (btRayAabb2(from, cb.m_rayDirectionInverse, cb.m_signs, bounds, tmin, 0, cb.m_lambda_max))
        ids.push_back(static_cast<int>(id));
    }
    return ids;
  }
  Ids bulletBox(const btVector3& lo, const btVector3& hi) {
    Ids ids;
    for (std::size_t id = 0; id < myProxies.size(); ++id) {
      if (!myProxies[id]) continue;
      btVector3 bmin, bmax;
      mine.getAabb(myProxies[id], bmin, bmax);
      if (TestAabbAgainstAabb2(lo, hi, bmin, bmax)) ids.push_back(static_cast<int>(id));
    }
    return ids;
  }
};

// Rays over [lo, hi]^3: segments, along each axis, from inside a box, of zero length, box casts.
struct Query {
  std::string name;
  bpaccel::RayQuery ray;
};
std::vector<Query> rays(const std::vector<Aabb>& boxes, float lo, float hi, unsigned seed) {
  std::mt19937 rng(seed);
  auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  auto point = [&] { return std::array<float, 3>{uni(lo, hi), uni(lo, hi), uni(lo, hi)}; };
  std::vector<Query> q;
  for (int k = 0; k < 16; ++k) q.push_back({"segment", bpaccel::RayQuery::segment(point(), point())});
  for (int a = 0; a < 3; ++a) {
    auto from = point(), to = from;
    to[a] = a % 2 ? lo : hi;
    q.push_back({"along an axis", bpaccel::RayQuery::segment(from, to)});
  }
  for (int k = 0; k < 4; ++k) {
    const Aabb& b = boxes[rng() % boxes.size()];
    const std::array<float, 3> c = {(b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2, (b.min[2] + b.max[2]) / 2};
    q.push_back({"from inside a box", bpaccel::RayQuery::segment(c, point())});
    q.push_back({"zero length inside a box", bpaccel::RayQuery::segment(c, c)});
  }
  for (int k = 0; k < 3; ++k) {
    bpaccel::RayQuery cast = bpaccel::RayQuery::segment(point(), point());
    const float e = uni(0.1f, 2);
    cast.grow = {{-e, -e, -e / 2}, {e, e / 2, e}};
    q.push_back({"box cast", cast});
  }
  return q;
}

void expectSameAsDbvtAndBullet(TwoBroadPhases& both, const std::vector<Aabb>& boxes, float lo, float hi, unsigned seed,
                               bool dbvtLeavesExact, const std::string& scene) {
  for (const Query& q : rays(boxes, lo, hi, seed)) {
    Collect mine(q.ray), theirs(q.ray);
    const btVector3 from = vec(q.ray.from), to = from, gmin = vec(q.ray.grow.min), gmax = vec(q.ray.grow.max);
    both.mine.rayTest(from, to, mine, gmin, gmax);
    both.dbvt.rayTest(from, to, theirs, gmin, gmax);
    const Ids exact = both.bulletRay(from, mine, gmin, gmax);
    ASSERT_EQ(mine.sorted(), exact) << scene << ": " << q.name;
    ASSERT_EQ(mine.ids.size(), exact.size()) << scene << ": " << q.name << " reported a proxy twice";
    const Ids dbvt = theirs.sorted();
    if (dbvtLeavesExact)
      ASSERT_EQ(dbvt, exact) << scene << ": " << q.name;
    else
      ASSERT_TRUE(std::includes(dbvt.begin(), dbvt.end(), exact.begin(), exact.end())) << scene << ": " << q.name;
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> coord(lo, hi), size(0, (hi - lo) / 6);
  for (int k = 0; k < 20; ++k) {
    const float x = coord(rng), y = coord(rng), z = coord(rng), e = size(rng);
    const btVector3 qlo(x, y, z), qhi(x + e, y + e * 0.5f, z + e);
    CollectBox mine, theirs;
    both.mine.aabbTest(qlo, qhi, mine);
    both.dbvt.aabbTest(qlo, qhi, theirs);
    const Ids exact = both.bulletBox(qlo, qhi);
    ASSERT_EQ(mine.sorted(), exact) << scene << ": box " << k;
    const Ids dbvt = theirs.sorted();
    if (dbvtLeavesExact) ASSERT_EQ(dbvt, exact) << scene << ": box " << k;
  }
}

// On proxies just created, btDbvtBroadphase's leaves are the exact boxes:
// both report the very same proxies for every query.
TEST(DropInQueries, SameProxiesAsDbvtOnFreshProxies) {
  for (const std::size_t n : {1u, 7u, 100u, 2000u})
    for (const auto& [name, boxes] : bpaccel::testing::adversarialScenes(n, static_cast<unsigned>(n) + 1)) {
      // Bullet's own tree needs finite boxes of finite size.
      if (name == "infinities" || name == "huge and tiny magnitudes" || name == "signed zeros") continue;
      TwoBroadPhases both;
      for (std::size_t i = 0; i < boxes.size(); ++i) both.add(static_cast<int>(i), boxes[i]);
      expectSameAsDbvtAndBullet(both, boxes, -110, 110, static_cast<unsigned>(n), true, name);
    }
}

// Proxies moved (setAabb), created and destroyed between frames and between
// queries: every query still gives exactly what Bullet's tests accept proxy by
// proxy, and btDbvtBroadphase (whose moved leaves are enlarged) a superset.
TEST(DropInQueries, ExactAfterMovesCreationsAndRemovals) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> coord(0, 60), extent(0, 3);
  auto randomBox = [&] {
    const float x = coord(rng), y = coord(rng), z = coord(rng);
    return Aabb{{x, y, z}, {x + extent(rng), y + extent(rng), z + extent(rng)}};
  };
  TwoBroadPhases both;
  std::vector<Aabb> boxes(1500);
  for (std::size_t i = 0; i < boxes.size(); ++i) both.add(static_cast<int>(i), boxes[i] = randomBox());
  for (int round = 0; round < 8; ++round) {
    const int moves = round % 2 ? 1500 : 20;  // a whole frame's moves, or a few between queries
    for (int m = 0; m < moves; ++m) {
      const std::size_t id = rng() % boxes.size();
      if (!both.myProxies[id]) continue;
      boxes[id] = randomBox();
      both.mine.setAabb(both.myProxies[id], vec(boxes[id].min), vec(boxes[id].max), &both.dispatcher);
      both.dbvt.setAabb(both.dbvtProxies[id], vec(boxes[id].min), vec(boxes[id].max), &both.dispatcher);
    }
    for (int c = 0; c < 10; ++c) {  // ten removals, ten new proxies
      const std::size_t id = rng() % boxes.size();
      if (both.myProxies[id]) {
        both.mine.destroyProxy(both.myProxies[id], &both.dispatcher);
        both.dbvt.destroyProxy(both.dbvtProxies[id], &both.dispatcher);
        both.myProxies[id] = both.dbvtProxies[id] = nullptr;
      }
      boxes.push_back(randomBox());
      both.add(static_cast<int>(boxes.size() - 1), boxes.back());
    }
    if (round % 3 == 0) {
      both.mine.calculateOverlappingPairs(&both.dispatcher);
      both.dbvt.calculateOverlappingPairs(&both.dispatcher);
    }
    expectSameAsDbvtAndBullet(both, boxes, -2, 62, static_cast<unsigned>(round), false,
                              "round " + std::to_string(round));
  }
  EXPECT_GE(both.mine.queryIndex().builds(), 4u);
}

// A callback that shortens the ray to each candidate's entry (a closest-hit
// search): each proxy it gets met the ray as it stood then, and every proxy
// the shortened ray meets was reported.
TEST(DropInQueries, HonoursARayTheCallbackShortens) {
  const auto boxes = bpaccel::testing::scatteredBoxes(3000, 8, 0, 40, 0.5f, 3);
  TwoBroadPhases both;
  for (std::size_t i = 0; i < boxes.size(); ++i) both.add(static_cast<int>(i), boxes[i]);
  struct Shorten final : btBroadphaseRayCallback {
    const std::vector<Aabb>* boxes = nullptr;
    bpaccel::RayQuery original;
    int wrong = 0;
    Ids ids;
    bool process(const btBroadphaseProxy* proxy) override {
      const int id = static_cast<int>(reinterpret_cast<std::intptr_t>(proxy->m_clientObject));
      if (!bpaccel::rayMeetsBox(original, (*boxes)[static_cast<std::size_t>(id)], m_lambda_max)) ++wrong;
      ids.push_back(id);
      m_lambda_max *= 0.6f;
      return true;
    }
  };
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> coord(0, 40);
  int shortened = 0;
  for (int r = 0; r < 100; ++r) {
    Shorten cb;
    cb.boxes = &boxes;
    cb.original = bpaccel::RayQuery::segment({coord(rng), coord(rng), coord(rng)}, {coord(rng), coord(rng), coord(rng)});
    bpaccel::aimRay(cb, cb.original);
    both.mine.rayTest(vec(cb.original.from), vec(cb.original.from), cb);
    EXPECT_EQ(cb.wrong, 0) << "ray " << r;
    std::sort(cb.ids.begin(), cb.ids.end());
    for (std::size_t id = 0; id < boxes.size(); ++id)
      if (bpaccel::rayMeetsBox(cb.original, boxes[id], cb.m_lambda_max))
        EXPECT_TRUE(std::binary_search(cb.ids.begin(), cb.ids.end(), static_cast<int>(id))) << "ray " << r;
    shortened += cb.ids.size() > 1;
  }
  EXPECT_GT(shortened, 20);
}

}  // namespace
