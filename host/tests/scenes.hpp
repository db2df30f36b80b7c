#pragma once
// Test scenes and the plain float reference every backend must match.

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/keys.hpp"
#include "core/types.hpp"

namespace bpaccel::testing {

/// All pairs by the definition, on the floats themselves (not on keys).
inline std::vector<Pair> bruteForce(const std::vector<Aabb>& boxes) {
  std::vector<Pair> pairs;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      bool hit = true;
      for (int a = 0; a < 3; ++a)
        hit = hit && boxes[i].min[a] <= boxes[j].max[a] && boxes[j].min[a] <= boxes[i].max[a];
      if (hit) pairs.emplace_back(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(j));
    }
  return pairs;
}

/// The same floats bit for bit (-0 is not 0).
inline bool sameBits(const Aabb& a, const Aabb& b) {
  for (int k = 0; k < 3; ++k)
    if (std::bit_cast<std::uint32_t>(a.min[k]) != std::bit_cast<std::uint32_t>(b.min[k]) ||
        std::bit_cast<std::uint32_t>(a.max[k]) != std::bit_cast<std::uint32_t>(b.max[k]))
      return false;
  return true;
}

/// All pairs by the definition, on keys (for scenes given as keys).
inline std::vector<Pair> bruteForceKeys(const std::vector<KeyBox>& keys) {
  std::vector<Pair> pairs;
  for (std::uint32_t i = 0; i < keys.size(); ++i)
    for (std::uint32_t j = i + 1; j < keys.size(); ++j)
      if (overlaps(keys[i], keys[j])) pairs.emplace_back(i, j);
  return pairs;
}

inline std::vector<Pair> sorted(std::vector<Pair> p) {
  std::sort(p.begin(), p.end());
  return p;
}

/// The boxes as keys (toKeys).
inline std::vector<KeyBox> keysOf(const std::vector<Aabb>& boxes) {
  std::vector<KeyBox> keys;
  toKeys(boxes, keys);
  return keys;
}

inline Aabb box(float x0, float y0, float z0, float x1, float y1, float z1) { return {{x0, y0, z0}, {x1, y1, z1}}; }

/// n boxes scattered uniformly: min corner in [lo, hi) on each axis, each
/// extent in [extentLo, extentHi).
inline std::vector<Aabb> scatteredBoxes(std::size_t n, unsigned seed, float lo, float hi, float extentLo,
                                        float extentHi) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> pos(lo, hi), ext(extentLo, extentHi);
  std::vector<Aabb> boxes(n);
  for (auto& b : boxes) {
    const float x = pos(gen), y = pos(gen), z = pos(gen);
    b = box(x, y, z, x + ext(gen), y + ext(gen), z + ext(gen));
  }
  return boxes;
}

/// Named scenes that stress exactness.
inline std::vector<std::pair<std::string, std::vector<Aabb>>> adversarialScenes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  auto uni = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
  auto pick = [&](int k) { return static_cast<int>(rng() % static_cast<unsigned>(k)); };
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<std::pair<std::string, std::vector<Aabb>>> scenes;
  auto make = [&](const std::string& name, auto gen) {
    std::vector<Aabb> v(n);
    for (auto& b : v) b = gen();
    scenes.emplace_back(name, std::move(v));
  };
  make("uniform", [&] {
    const float x = uni(-100, 100), y = uni(-100, 100), z = uni(-100, 100), e = uni(0, 12);
    return box(x, y, z, x + e, y + uni(0, 12), z + uni(0, 12));
  });
  make("clusters", [&] {
    const float c = static_cast<float>(pick(3)) * 50.0f;
    const float x = c + uni(-3, 3), y = c + uni(-3, 3), z = uni(-3, 3);
    return box(x, y, z, x + uni(0, 2), y + uni(0, 2), z + uni(0, 2));
  });
  make("touching faces on a grid", [&] {
    const float x = static_cast<float>(pick(6)), y = static_cast<float>(pick(6)), z = static_cast<float>(pick(6));
    return box(x, y, z, x + static_cast<float>(pick(2)), y + 1, z + static_cast<float>(pick(2)));
  });
  make("zero extent and identical", [&] {
    if (pick(2)) return box(1, 2, 3, 4, 5, 6);
    const float x = static_cast<float>(pick(5)), y = static_cast<float>(pick(7)), z = static_cast<float>(pick(7));
    return box(x, y, z, x, y, z);
  });
  make("signed zeros", [&] {
    const float lo = pick(2) ? -0.0f : 0.0f, hi = pick(2) ? -0.0f : 0.0f;
    const float a = uni(-1, 0), b = uni(0, 1);
    switch (pick(3)) {
      case 0: return box(a, a, a, lo, lo, lo);  // ends at zero
      case 1: return box(hi, hi, hi, b, b, b);  // starts at zero
      default: return box(a, lo, a, b, hi, b);
    }
  });
  make("infinities", [&] {
    const float x = uni(-10, 10);
    switch (pick(4)) {
      case 0: return box(-inf, -inf, -inf, inf, inf, inf);
      case 1: return box(x, -inf, x, x + 1, x, x + 1);
      case 2: return box(inf, inf, inf, inf, inf, inf);
      default: return box(x, x, x, x + uni(0, 3), inf, x + uni(0, 3));
    }
  });
  make("huge and tiny magnitudes", [&] {
    if (pick(2)) {
      const float x = uni(-1, 1) * 3e38f;
      return box(x, -3e38f, x, std::min(x + 1e37f, 3.4e38f), 3e38f, std::min(x + 1e37f, 3.4e38f));
    }
    const float x = uni(-1, 1) * 1e-38f, e = 1e-45f * static_cast<float>(pick(4));  // denormals
    return box(x, x, x, x + e, x + e, x + e);
  });
  make("huge boxes straddling everything", [&] {
    if (pick(4) == 0) return box(-1000, -1000, -1000, 1000, 1000, 1000);
    const float x = uni(-50, 50), y = uni(-50, 50), z = uni(-50, 50);
    return box(x, y, z, x + 1, y + 1, z + 1);
  });
  make("stacked at one point", [&] { return box(7, 7, 7, 7, 7, 7); });
  return scenes;
}

}  // namespace bpaccel::testing
