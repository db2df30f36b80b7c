#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "core/all_pairs_kernel.hpp"
#include "core/keys.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

TEST(AllPairsKernel, SimdGivesTheScalarPairsInTheSameOrderForEverySize) {
  const AllPairsKernel simd, scalar = AllPairsKernel::scalar();
  AllPairsKernel::Scratch scratch;
  std::vector<std::size_t> sizes;
  for (std::size_t n = 0; n <= 40; ++n) sizes.push_back(n);  // every remainder modulo the vector width
  sizes.push_back(257);
  for (std::size_t n : sizes)
    for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 3)) {
      std::vector<KeyBox> keys;
      toKeys(boxes, keys);
      std::vector<Pair> fromSimd, fromScalar;
      simd.run(keys, fromSimd, scratch);
      scalar.run(keys, fromScalar, scratch);
      const std::string label = name + " n=" + std::to_string(n) + " isa " + std::string(simd.isa());
      EXPECT_EQ(fromSimd, fromScalar) << label;
      EXPECT_EQ(fromScalar, bruteForce(boxes)) << label;  // i then j order is the brute force's order
    }
}

TEST(AllPairsKernel, BoxesOverEveryKeyPairOnlyWithBoxesNotWithThePadding) {
  // Keys 0 and 2^32-1 are the padding's own values: a box over all of key
  // space overlaps the padding lanes, which must never become pairs.
  const std::uint32_t top = ~0u;
  const AllPairsKernel simd;
  AllPairsKernel::Scratch scratch;
  for (std::size_t n = 1; n <= 19; ++n) {
    std::vector<KeyBox> keys(n, KeyBox{{0, 0, 0}, {top, top, top}});
    std::vector<Pair> pairs, all;
    simd.run(keys, pairs, scratch);
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t j = i + 1; j < n; ++j) all.emplace_back(i, j);
    EXPECT_EQ(pairs, all) << "n=" << n << " isa " << simd.isa();
  }
}
