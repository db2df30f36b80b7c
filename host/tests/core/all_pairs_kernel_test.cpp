#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
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

namespace {

// The ISAs this CPU runs, each as its own kernel.
std::vector<AllPairsKernel> everyKernel() {
  std::vector<AllPairsKernel> kernels{AllPairsKernel::scalar()};
  for (const char* isa : {"sse2", "avx2"}) try {
      kernels.push_back(AllPairsKernel::forIsa(isa));
    } catch (const std::invalid_argument&) {
    }
  return kernels;
}

}  // namespace

TEST(AllPairsKernel, SweepAndAllPairsGiveTheOwnedPairsAsSceneIndicesOnEveryIsa) {
  // A cell that is part of a scene: its boxes are the scene's at `ids`, some
  // with below() bits; a pair is owned where the bits share no axis.
  std::mt19937 rng(9);
  for (const AllPairsKernel& kernel : everyKernel())
    for (std::size_t n : {0, 1, 2, 7, 8, 9, 17, 97, 300})
      for (const auto& [name, boxes] : adversarialScenes(n, static_cast<unsigned>(n) + 5)) {
        const std::vector<KeyBox> keys = keysOf(boxes);
        std::vector<std::uint32_t> ids(n);
        std::iota(ids.begin(), ids.end(), 0u);
        std::shuffle(ids.begin(), ids.end(), rng);
        std::vector<std::uint8_t> below(n);
        for (auto& b : below) b = static_cast<std::uint8_t>(rng() % 8);
        std::vector<Pair> expected;
        for (std::size_t i = 0; i < n; ++i)
          for (std::size_t j = i + 1; j < n; ++j)
            if (overlaps(keys[ids[i]], keys[ids[j]]) && (below[i] & below[j]) == 0)
              expected.emplace_back(std::min(ids[i], ids[j]), std::max(ids[i], ids[j]));
        std::sort(expected.begin(), expected.end());
        const CellBoxes cell{keys, ids, below, true};
        AllPairsKernel::Scratch scratch;
        std::vector<Pair> all, swept;
        kernel.allPairs(cell, all, scratch);
        kernel.sweep(cell, swept, scratch);
        const std::string label = name + " n=" + std::to_string(n) + " isa " + std::string(kernel.isa());
        EXPECT_EQ(sorted(all), expected) << label;
        EXPECT_EQ(sorted(swept), expected) << label;
        // Without bits every overlapping pair is the cell's.
        std::vector<Pair> unowned;
        kernel.sweep({keys, ids, {}, true}, unowned, scratch);
        EXPECT_EQ(sorted(unowned), bruteForce(boxes)) << label;
      }
}

TEST(AllPairsKernel, SweepAppendsToPairsAlreadyThere) {
  const auto boxes = scatteredBoxes(200, 4, 0, 10, 0.5f, 2);
  const std::vector<KeyBox> keys = keysOf(boxes);
  AllPairsKernel::Scratch scratch;
  std::vector<Pair> out{{7, 9}};
  AllPairsKernel().sweep({keys}, out, scratch);
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.front(), (Pair{7, 9}));
  out.erase(out.begin());
  EXPECT_EQ(sorted(out), bruteForce(boxes));
}

TEST(AllPairsKernel, RefusesAnInstructionSetItDoesNotKnow) {
  EXPECT_THROW(AllPairsKernel::forIsa("avx512"), std::invalid_argument);
  EXPECT_EQ(AllPairsKernel::forIsa("scalar").isa(), "scalar");
}
