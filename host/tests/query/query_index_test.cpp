// QueryIndex and BoxTree: every ray and box query equals the brute force
// (rayMeetsBox, boxesOverlap over every box) on many scenes, between changes too.

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "query/box_tree.hpp"
#include "query/query_index.hpp"
#include "query/ray.hpp"
#include "scenes.hpp"

namespace {

using bpaccel::Aabb;
using bpaccel::QueryIndex;
using bpaccel::RayQuery;
using Ids = std::vector<std::uint32_t>;
constexpr float kInf = std::numeric_limits<float>::infinity();

Ids sortedIds(Ids ids) {
  std::sort(ids.begin(), ids.end());
  return ids;
}

// The reference: every live box tested, in id order.
Ids bruteRay(const std::map<std::uint32_t, Aabb>& boxes, const RayQuery& ray) {
  Ids ids;
  for (const auto& [id, b] : boxes)
    if (bpaccel::rayMeetsBox(ray, b, ray.lambdaMax)) ids.push_back(id);
  return ids;
}

Ids bruteBox(const std::map<std::uint32_t, Aabb>& boxes, const Aabb& q) {
  Ids ids;
  for (const auto& [id, b] : boxes)
    if (bpaccel::boxesOverlap(b, q)) ids.push_back(id);
  return ids;
}

Ids indexRay(QueryIndex& index, RayQuery ray) {
  Ids ids;
  index.rayTest(ray, [&](std::uint32_t id) { ids.push_back(id); });
  return sortedIds(ids);  // sorted: also shows no id came twice, below
}

Ids indexBox(QueryIndex& index, const Aabb& q) {
  Ids ids;
  index.aabbTest(q, [&](std::uint32_t id) { ids.push_back(id); });
  return sortedIds(ids);
}

// Rays a user casts, over a scene whose finite part lies in [lo, hi]: random
// segments, along each axis (zero direction components), from inside a box,
// of zero length, along a box's face, box casts, and rays the tree cannot
// order (infinite, zero or NaN components), which go box by box.
std::vector<std::pair<std::string, RayQuery>> raysFor(const std::vector<Aabb>& boxes, float lo, float hi,
                                                      unsigned seed) {
  std::mt19937 rng(seed);
  auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  auto point = [&] { return std::array<float, 3>{uni(lo, hi), uni(lo, hi), uni(lo, hi)}; };
  auto finiteBox = [&] {
    for (int tries = 0; tries < 20; ++tries) {
      const Aabb& b = boxes[rng() % boxes.size()];
      if (std::isfinite(b.min[0] + b.max[0] + b.min[1] + b.max[1] + b.min[2] + b.max[2])) return b;
    }
    return Aabb{{0, 0, 0}, {0, 0, 0}};
  };
  std::vector<std::pair<std::string, RayQuery>> rays;
  for (int k = 0; k < 12; ++k) rays.emplace_back("segment", RayQuery::segment(point(), point()));
  for (int a = 0; a < 3; ++a)
    for (const float sign : {1.0f, -1.0f}) {
      auto from = point(), to = from;
      to[a] += sign * (hi - lo);
      rays.emplace_back("along an axis", RayQuery::segment(from, to));
    }
  if (!boxes.empty()) {
    for (int k = 0; k < 4; ++k) {
      const Aabb b = finiteBox();
      const std::array<float, 3> c = {b.min[0] / 2 + b.max[0] / 2, b.min[1] / 2 + b.max[1] / 2,
                                      b.min[2] / 2 + b.max[2] / 2};
      rays.emplace_back("from inside a box", RayQuery::segment(c, point()));
      rays.emplace_back("zero length inside a box", RayQuery::segment(c, c));
      const std::array<float, 3> corner = {b.min[0], b.min[1], b.min[2]};
      auto along = corner;
      along[k % 3] = b.max[k % 3] + 1;
      rays.emplace_back("along a face", RayQuery::segment(corner, along));
    }
  }
  const auto p = point();
  rays.emplace_back("zero length", RayQuery::segment(p, p));
  for (int k = 0; k < 3; ++k) {
    RayQuery cast = RayQuery::segment(point(), point());
    const float e = uni(0, 3);
    cast.grow = {{-e, -e / 2, 0}, {e, e / 2, e}};
    rays.emplace_back("box cast", cast);
  }
  RayQuery odd = RayQuery::segment(point(), point());
  odd.inverseDirection[1] = kInf;
  rays.emplace_back("infinite inverse direction", odd);
  odd.inverseDirection[1] = 0;
  rays.emplace_back("zero inverse direction", odd);
  odd.inverseDirection[1] = std::nanf("");
  rays.emplace_back("NaN inverse direction", odd);
  RayQuery far = RayQuery::segment(point(), point());
  far.lambdaMax = kInf;
  rays.emplace_back("endless", far);
  return rays;
}

std::vector<Aabb> queryBoxes(float lo, float hi, unsigned seed) {
  std::mt19937 rng(seed);
  auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  std::vector<Aabb> q;
  for (int k = 0; k < 10; ++k) {
    const float x = uni(lo, hi), y = uni(lo, hi), z = uni(lo, hi), e = uni(0, (hi - lo) / 8);
    q.push_back({{x, y, z}, {x + e, y + e, z + e}});
  }
  q.push_back({{lo, lo, lo}, {lo, lo, lo}});  // a point
  q.push_back({{-kInf, -kInf, -kInf}, {kInf, kInf, kInf}});
  q.push_back({{1, 1, 1}, {0, 0, 0}});  // inverted: Bullet's test still answers
  q.push_back({{std::nanf(""), 0, 0}, {1, 1, 1}});
  return q;
}

void expectEveryQueryExact(QueryIndex& index, const std::map<std::uint32_t, Aabb>& live,
                           const std::vector<Aabb>& boxes, const std::string& scene, unsigned seed) {
  float lo = -10, hi = 10;
  for (const Aabb& b : boxes)
    for (int a = 0; a < 3; ++a) {
      if (std::isfinite(b.min[a]) && std::fabs(b.min[a]) < 1e6f) lo = std::min(lo, b.min[a]);
      if (std::isfinite(b.max[a]) && std::fabs(b.max[a]) < 1e6f) hi = std::max(hi, b.max[a]);
    }
  for (const auto& [name, ray] : raysFor(boxes, lo - 2, hi + 2, seed))
    ASSERT_EQ(indexRay(index, ray), bruteRay(live, ray)) << scene << ", ray " << name;
  for (const Aabb& q : queryBoxes(lo - 2, hi + 2, seed))
    ASSERT_EQ(indexBox(index, q), bruteBox(live, q)) << scene << ", box from " << q.min[0];
}

std::map<std::uint32_t, Aabb> asMap(const std::vector<Aabb>& boxes) {
  std::map<std::uint32_t, Aabb> m;
  for (std::size_t i = 0; i < boxes.size(); ++i) m[static_cast<std::uint32_t>(i)] = boxes[i];
  return m;
}

TEST(QueryIndex, EveryRayAndBoxQueryEqualsBruteForceOnAdversarialScenes) {
  for (const std::size_t n : {1u, 3u, 4u, 5u, 17u, 64u, 300u})
    for (const auto& [name, boxes] : bpaccel::testing::adversarialScenes(n, static_cast<unsigned>(n))) {
      QueryIndex index;
      index.assign(boxes);
      expectEveryQueryExact(index, asMap(boxes), boxes, name + ", n=" + std::to_string(n), static_cast<unsigned>(n));
    }
}

TEST(QueryIndex, EveryQueryEqualsBruteForceOnLargerUniformScenes) {
  for (const unsigned seed : {1u, 2u, 3u}) {
    const auto boxes = bpaccel::testing::scatteredBoxes(5000, seed, 0, 100, 0.2f, 3);
    QueryIndex index;
    index.assign(boxes);
    expectEveryQueryExact(index, asMap(boxes), boxes, "scattered", seed);
  }
}

TEST(QueryIndex, AnEmptyIndexFindsNothing) {
  QueryIndex index;
  RayQuery ray = RayQuery::segment({0, 0, 0}, {1, 1, 1});
  EXPECT_TRUE(indexRay(index, ray).empty());
  EXPECT_TRUE(indexBox(index, {{-1, -1, -1}, {1, 1, 1}}).empty());
  index.assign({});
  EXPECT_TRUE(indexRay(index, ray).empty());
}

// Set, move and erase boxes between queries, a few at a time (the loose
// boxes beside the tree) and many at a time (a rebuild): every query exact.
TEST(QueryIndex, QueriesStayExactBetweenChanges) {
  std::mt19937 rng(11);
  auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  auto randomBox = [&] {
    const float x = uni(0, 50), y = uni(0, 50), z = uni(0, 50);
    return Aabb{{x, y, z}, {x + uni(0, 4), y + uni(0, 4), z + uni(0, 4)}};
  };
  QueryIndex index;
  std::map<std::uint32_t, Aabb> live;
  for (std::uint32_t id = 0; id < 600; ++id) {
    live[id] = randomBox();
    index.set(id, live[id]);
  }
  index.prepare();
  std::uint64_t buildsAfterFewChanges = 0;
  for (int round = 0; round < 24; ++round) {
    const int changes = round % 3 == 2 ? 400 : static_cast<int>(rng() % 40);
    const std::uint64_t before = index.builds();
    for (int c = 0; c < changes; ++c) {
      const std::uint32_t id = static_cast<std::uint32_t>(rng() % 700);
      if (live.count(id) && rng() % 3 == 0) {
        index.erase(id);
        live.erase(id);
      } else {
        live[id] = randomBox();
        index.set(id, live[id]);
      }
    }
    std::vector<Aabb> boxes;
    for (const auto& [id, b] : live) boxes.push_back(b);
    ASSERT_EQ(index.size(), live.size());
    expectEveryQueryExact(index, live, boxes, "round " + std::to_string(round), static_cast<unsigned>(round));
    if (round % 3 == 0) buildsAfterFewChanges += index.builds() - before;  // the first changes since a build
    if (round % 3 == 2) EXPECT_EQ(index.builds(), before + 1) << "many changes rebuild the tree once";
  }
  EXPECT_EQ(buildsAfterFewChanges, 0u) << "a few changes are served beside the tree";
}

TEST(QueryIndex, RejectsBadBoxesNamingThem) {
  QueryIndex index;
  try {
    index.set(7, {{0, std::nanf(""), 0}, {1, 1, 1}});
    FAIL() << "NaN accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("box 7 has NaN on y"), std::string::npos) << e.what();
  }
  try {
    index.assign(std::vector<Aabb>{{{0, 0, 0}, {1, 1, 1}}, {{0, 0, 2}, {1, 1, 1}}});
    FAIL() << "min > max accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("box 1 has min 2 > max 1 on z"), std::string::npos) << e.what();
  }
  EXPECT_THROW(index.erase(3), std::invalid_argument);
  EXPECT_EQ(index.size(), 0u);
}

// A receiver that shortens the ray to each hit's entry (a closest-hit
// query): each box it is told of met the ray as it stood then, and every box
// the final ray meets was reported.
TEST(QueryIndex, AReceiverMayShortenTheRayAsItGoes) {
  const auto boxes = bpaccel::testing::scatteredBoxes(3000, 5, 0, 40, 0.5f, 3);
  QueryIndex index;
  index.assign(boxes);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> coord(0, 40);
  int shortened = 0;
  for (int r = 0; r < 200; ++r) {
    RayQuery ray = RayQuery::segment({coord(rng), coord(rng), coord(rng)}, {coord(rng), coord(rng), coord(rng)});
    const RayQuery original = ray;
    Ids reported;
    index.rayTest(ray, [&](std::uint32_t id) {
      EXPECT_TRUE(bpaccel::rayMeetsBox(original, boxes[id], ray.lambdaMax)) << "ray " << r << " box " << id;
      reported.push_back(id);
      ray.lambdaMax *= 0.5f;  // shorten by half each time
    });
    shortened += reported.size() > 1;
    reported = sortedIds(reported);
    EXPECT_TRUE(std::adjacent_find(reported.begin(), reported.end()) == reported.end());
    for (std::uint32_t id = 0; id < boxes.size(); ++id)
      if (bpaccel::rayMeetsBox(original, boxes[id], ray.lambdaMax))
        EXPECT_TRUE(std::binary_search(reported.begin(), reported.end(), id)) << "ray " << r << " missed " << id;
  }
  EXPECT_GT(shortened, 50);
}

// The argument the tree rests on, checked directly: a box that holds another
// is met by every ray that meets the inner one (monotone float operations),
// here on boxes whose faces lie exactly on the rays' paths.
TEST(QueryIndex, ARayThatMeetsABoxMeetsEveryBoxAroundIt) {
  std::mt19937 rng(9);
  auto uni = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(rng); };
  int met = 0;
  for (int k = 0; k < 100000; ++k) {
    const float x = std::round(uni(-8, 8)), y = std::round(uni(-8, 8)), z = std::round(uni(-8, 8));
    const Aabb inner{{x, y, z}, {x + std::round(uni(0, 3)), y + std::round(uni(0, 3)), z + std::round(uni(0, 3))}};
    const Aabb outer{{inner.min[0] - std::round(uni(0, 2)), inner.min[1], inner.min[2] - uni(0, 1)},
                     {inner.max[0], inner.max[1] + std::round(uni(0, 2)), inner.max[2]}};
    RayQuery ray = RayQuery::segment({std::round(uni(-9, 9)), std::round(uni(-9, 9)), std::round(uni(-9, 9))},
                                     {std::round(uni(-9, 9)), std::round(uni(-9, 9)), std::round(uni(-9, 9))});
    if (k % 2) ray.grow = {{-1, 0, -0.5f}, {0, 1, 0.5f}};
    if (!bpaccel::BoxTree::walksTree(ray) || !bpaccel::rayMeetsBox(ray, inner, ray.lambdaMax)) continue;
    ++met;
    ASSERT_TRUE(bpaccel::rayMeetsBox(ray, outer, ray.lambdaMax)) << k;
  }
  EXPECT_GT(met, 1000);
}

TEST(QueryIndex, SegmentIsBulletsRay) {
  const RayQuery ray = RayQuery::segment({1, 2, 3}, {1, 2, -1});
  EXPECT_EQ(ray.inverseDirection[0], bpaccel::kLargeInverse);
  EXPECT_EQ(ray.inverseDirection[1], bpaccel::kLargeInverse);
  EXPECT_EQ(ray.inverseDirection[2], -1.0f);
  EXPECT_EQ(ray.signs, (std::array<std::uint32_t, 3>{0, 0, 1}));
  EXPECT_FLOAT_EQ(ray.lambdaMax, 4.0f);
  const RayQuery point = RayQuery::segment({1, 2, 3}, {1, 2, 3});
  EXPECT_EQ(point.lambdaMax, 0.0f);
  EXPECT_TRUE(bpaccel::rayMeetsBox(point, {{0, 0, 0}, {2, 3, 4}}, 0));
  EXPECT_FALSE(bpaccel::rayMeetsBox(point, {{1, 0, 0}, {2, 3, 4}}, 0)) << "a zero-length ray needs the point inside";
}

}  // namespace
