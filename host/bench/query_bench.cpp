#include "query_bench.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <numeric>
#include <random>
#include <stdexcept>

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <LinearMath/btAabbUtil2.h>
#include <btBulletDynamicsCommon.h>
#include <fmt/format.h>

#include "bullet/bullet_drop_in.hpp"
#include "core/median.hpp"
#include "device/cpu_backend.hpp"
#include "query/ray.hpp"

namespace bpaccel {
namespace {

using Clock = std::chrono::steady_clock;
using Ids = std::vector<int>;

int idOf(const btBroadphaseProxy* p) { return static_cast<int>(reinterpret_cast<std::intptr_t>(p->m_clientObject)); }

// Counts the proxies a callback is given, and keeps them when asked (outside the timed rounds).
struct Tally {
  explicit Tally(Ids* keep) : keep_(keep) {}
  void count(const btBroadphaseProxy* proxy) {
    ++hits;
    if (keep_) keep_->push_back(idOf(proxy));
  }
  std::size_t hits = 0;

 private:
  Ids* keep_;
};

// With the fields btCollisionWorld::rayTest gives its callback.
struct RayCounter final : btBroadphaseRayCallback, Tally {
  explicit RayCounter(const RayQuery& ray, Ids* keep = nullptr) : Tally(keep) { aimRay(*this, ray); }
  bool process(const btBroadphaseProxy* proxy) override {
    count(proxy);
    return true;
  }
};

struct BoxCounter final : btBroadphaseAabbCallback, Tally {
  explicit BoxCounter(Ids* keep = nullptr) : Tally(keep) {}
  bool process(const btBroadphaseProxy* proxy) override {
    count(proxy);
    return true;
  }
};

// One kind of query: rays of one length, or boxes.
struct QueryKind {
  std::string name;
  std::vector<RayQuery> rays;  // empty for boxes
  std::vector<Aabb> boxes;
  std::size_t size() const { return rays.empty() ? boxes.size() : rays.size(); }
};

std::vector<QueryKind> queryKinds(const QueryBenchConfig& c, float edge, std::uint32_t seed) {
  std::mt19937 rng(seed);
  auto uni = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
  auto point = [&] { return std::array<float, 3>{uni(0, edge), uni(0, edge), uni(0, edge)}; };
  QueryKind across{"ray across the cube (point to point)", {}, {}}, shortRay{"ray of length 5", {}, {}},
      box{"box of edge 4", {}, {}};
  for (std::size_t k = 0; k < c.perKind; ++k) {
    across.rays.push_back(RayQuery::segment(point(), point()));
    const auto from = point();
    RayQuery r = RayQuery::segment(from, point());
    const std::array<float, 3> to = {from[0] + 5 / r.inverseDirection[0], from[1] + 5 / r.inverseDirection[1],
                                     from[2] + 5 / r.inverseDirection[2]};
    shortRay.rays.push_back(RayQuery::segment(from, to));
  }
  for (std::size_t k = 0; k < c.perKind; ++k) {
    const auto p = point();
    box.boxes.push_back({{p[0] - 2, p[1] - 2, p[2] - 2}, {p[0] + 2, p[1] + 2, p[2] + 2}});
  }
  return {across, shortRay, box};
}

btVector3 vec(const std::array<float, 3>& v) { return {v[0], v[1], v[2]}; }

// Runs every query of `kind` on `bp`; keeps each one's proxies, sorted, when `answers` is given.
std::size_t runQueries(btBroadphaseInterface& bp, const QueryKind& kind, std::vector<Ids>* answers) {
  std::size_t hits = 0;
  for (std::size_t q = 0; q < kind.size(); ++q) {
    Ids* keep = answers ? &(*answers)[q] : nullptr;
    if (!kind.rays.empty()) {
      RayCounter cb(kind.rays[q], keep);
      bp.rayTest(vec(kind.rays[q].from), vec(kind.rays[q].from), cb);
      hits += cb.hits;
    } else {
      BoxCounter cb(keep);
      bp.aabbTest(vec(kind.boxes[q].min), vec(kind.boxes[q].max), cb);
      hits += cb.hits;
    }
    if (keep) std::sort(keep->begin(), keep->end());
  }
  return hits;
}

// Bullet's own tests on every proxy's exact box: what each query must report.
Ids exactAnswer(const std::vector<Aabb>& boxes, const QueryKind& kind, std::size_t q) {
  Ids ids;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const btVector3 lo = vec(boxes[i].min), hi = vec(boxes[i].max);
    bool hit;
    if (!kind.rays.empty()) {
      const RayCounter cb(kind.rays[q]);
      const btVector3 bounds[2] = {lo, hi};
      btScalar tmin;
      hit = btRayAabb2(vec(kind.rays[q].from), cb.m_rayDirectionInverse, cb.m_signs, bounds, tmin, 0, cb.m_lambda_max);
    } else {
      hit = TestAabbAgainstAabb2(vec(kind.boxes[q].min), vec(kind.boxes[q].max), lo, hi);
    }
    if (hit) ids.push_back(static_cast<int>(i));
  }
  return ids;
}

struct Contender {
  std::string name;
  std::unique_ptr<btBroadphaseInterface> bp;
  std::vector<btBroadphaseProxy*> proxies;
  std::vector<std::vector<double>> perQuerySeconds;  // per kind, one figure a round
  std::vector<std::uint64_t> extra, missing, hits;   // per kind, over the checked round
};

nlohmann::json runRow(const QueryBenchConfig& config, std::size_t objects,
                      const std::function<void(const std::string&)>& progress) {
  SceneConfig sc = config.scene;
  sc.objects = objects;
  progress(fmt::format("queries, n={}: scene", objects));
  BouncingCubeScene scene(sc);
  std::vector<Aabb> boxes;
  scene.aabbs(boxes);
  btDefaultCollisionConfiguration collisionConfig;
  btCollisionDispatcher dispatcher(&collisionConfig);
  std::vector<Contender> contenders;
  contenders.push_back({"btDbvtBroadphase", std::make_unique<btDbvtBroadphase>(), {}, {}, {}, {}, {}});
  contenders.push_back({"bpaccel::BulletDropIn, cpu backend", std::make_unique<BulletDropIn>(std::make_unique<CpuBackend>()),
                        {}, {}, {}, {}, {}});
  // btDbvtBroadphase frees a proxy only in destroyProxy: release every proxy before the broad phases go.
  struct ProxyRelease {
    std::vector<Contender>& contenders;
    btDispatcher* dispatcher;
    ~ProxyRelease() {
      for (auto& c : contenders)
        for (btBroadphaseProxy* p : c.proxies) c.bp->destroyProxy(p, dispatcher);
    }
  } release{contenders, &dispatcher};
  for (auto& c : contenders)
    for (std::size_t i = 0; i < boxes.size(); ++i)
      c.proxies.push_back(c.bp->createProxy(vec(boxes[i].min), vec(boxes[i].max), BOX_SHAPE_PROXYTYPE,
                                            reinterpret_cast<void*>(static_cast<std::intptr_t>(i)), 1, -1, &dispatcher));
  // Frames as a world runs them: every proxy moved, then the pairs found.
  double buildSeconds = 0;
  for (std::size_t f = 0; f < config.frames; ++f) {
    progress(fmt::format("queries, n={}: frame {}/{}", objects, f + 1, config.frames));
    scene.step();
    scene.aabbs(boxes);
    for (auto& c : contenders) {
      for (std::size_t i = 0; i < boxes.size(); ++i)
        c.bp->setAabb(c.proxies[i], vec(boxes[i].min), vec(boxes[i].max), &dispatcher);
      c.bp->calculateOverlappingPairs(&dispatcher);
    }
    // The drop-in's query tree, built as the frame's first query would build it.
    const auto t0 = Clock::now();
    static_cast<BulletDropIn&>(*contenders[1].bp).queryIndex().prepare();
    buildSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
  }
  const auto kinds = queryKinds(config, scene.cubeEdge(), sc.seed);
  for (auto& c : contenders) {
    c.perQuerySeconds.resize(kinds.size());
    c.extra.assign(kinds.size(), 0);
    c.missing.assign(kinds.size(), 0);
    c.hits.assign(kinds.size(), 0);
  }
  // Checked once, outside the timed rounds: each answer against Bullet's tests on every proxy.
  progress(fmt::format("queries, n={}: checking every answer", objects));
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    std::vector<std::vector<Ids>> answers(contenders.size(), std::vector<Ids>(kinds[k].size()));
    for (std::size_t c = 0; c < contenders.size(); ++c) runQueries(*contenders[c].bp, kinds[k], &answers[c]);
    for (std::size_t q = 0; q < kinds[k].size(); ++q) {
      const Ids exact = exactAnswer(boxes, kinds[k], q);
      for (std::size_t c = 0; c < contenders.size(); ++c) {
        const Ids& got = answers[c][q];
        Ids diff;
        std::set_difference(got.begin(), got.end(), exact.begin(), exact.end(), std::back_inserter(diff));
        contenders[c].extra[k] += diff.size();
        diff.clear();
        std::set_difference(exact.begin(), exact.end(), got.begin(), got.end(), std::back_inserter(diff));
        contenders[c].missing[k] += diff.size();
        contenders[c].hits[k] += got.size();
      }
    }
  }
  for (const auto& c : contenders)
    for (std::size_t k = 0; k < kinds.size(); ++k)
      if (c.missing[k] || (c.name != "btDbvtBroadphase" && c.extra[k]))
        throw std::runtime_error(fmt::format("queries, n={}: {} gave {} extra and {} missing proxies on {}", objects,
                                             c.name, c.extra[k], c.missing[k], kinds[k].name));
  std::mt19937 shuffler(sc.seed);
  std::vector<std::size_t> order(contenders.size());
  for (std::size_t r = 0; r < config.rounds; ++r) {
    progress(fmt::format("queries, n={}: round {}/{}", objects, r + 1, config.rounds));
    for (std::size_t k = 0; k < kinds.size(); ++k) {
      std::iota(order.begin(), order.end(), 0);
      std::shuffle(order.begin(), order.end(), shuffler);
      for (std::size_t c : order) {
        const auto t0 = Clock::now();
        runQueries(*contenders[c].bp, kinds[k], nullptr);
        contenders[c].perQuerySeconds[k].push_back(std::chrono::duration<double>(Clock::now() - t0).count() /
                                                   static_cast<double>(kinds[k].size()));
      }
    }
  }
  nlohmann::json methods = nlohmann::json::array();
  for (const auto& c : contenders) {
    nlohmann::json kindsJson = nlohmann::json::array();
    for (std::size_t k = 0; k < kinds.size(); ++k) {
      const auto& s = c.perQuerySeconds[k];
      kindsJson.push_back({{"query", kinds[k].name},
                           {"us_per_query", {{"median", median(s) * 1e6},
                                             {"min", *std::min_element(s.begin(), s.end()) * 1e6},
                                             {"max", *std::max_element(s.begin(), s.end()) * 1e6}}},
                           {"proxies_per_query", static_cast<double>(c.hits[k]) / static_cast<double>(kinds[k].size())},
                           {"extra_proxies", c.extra[k]},
                           {"missing_proxies", c.missing[k]}});
    }
    methods.push_back({{"name", c.name}, {"queries", kindsJson}});
  }
  return {{"objects", objects},
          {"frames_before", config.frames},
          {"queries_per_kind", kinds.front().size()},
          {"rounds", config.rounds},
          {"drop_in_tree_build_ms", buildSeconds * 1e3},
          {"methods", methods}};
}

}  // namespace

nlohmann::json runQueryBench(const QueryBenchConfig& config, const std::function<void(const std::string&)>& progress) {
  nlohmann::json rows = nlohmann::json::array();
  for (const std::size_t n : config.objectCounts) rows.push_back(runRow(config, n, progress));
  return {{"what", "measured: broad-phase rayTest and aabbTest on the bouncing cube's proxies after a few frames of "
                   "setAabb and calculateOverlappingPairs (btDbvtBroadphase as a world leaves it); time per query, "
                   "median over rounds, the drop-in's query tree built before the rounds (its build is "
                   "drop_in_tree_build_ms, paid once a frame by the first query after the proxies moved). Every "
                   "answer checked against btRayAabb2 / TestAabbAgainstAabb2 on every proxy's exact box: "
                   "btDbvtBroadphase's extra proxies come from its enlarged leaves"},
          {"rows", rows}};
}

std::string queryTable(const nlohmann::json& queries) {
  std::string t = "\nBroad-phase queries, microseconds per query (measured; median over rounds), proxies reported "
                  "per query, and extra proxies beyond Bullet's exact test:\n";
  for (const auto& row : queries["rows"]) {
    t += fmt::format("  n={} (the drop-in's query tree: {:.3f} ms to build, once a frame)\n",
                     row["objects"].get<std::size_t>(), row["drop_in_tree_build_ms"].get<double>());
    for (const auto& m : row["methods"])
      for (const auto& q : m["queries"])
        t += fmt::format("    {:<40} {:<40} {:>10.3f} us  {:>8.1f} proxies  {:>6} extra\n", m["name"].get<std::string>(),
                         q["query"].get<std::string>(), q["us_per_query"]["median"].get<double>(),
                         q["proxies_per_query"].get<double>(), q["extra_proxies"].get<std::uint64_t>());
  }
  return t;
}

}  // namespace bpaccel
