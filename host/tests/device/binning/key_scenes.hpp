#pragma once
// Key boxes for frames of the binning device: random scenes of four kinds
// inside a grid, for the model's tests and the RTL's.

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "core/types.hpp"

namespace bpaccel::testing {

/// A number in 0 .. k-1.
inline std::uint32_t below(std::mt19937& rng, std::uint32_t k) { return static_cast<std::uint32_t>(rng() % k); }

/// Boxes inside a grid of `dims` cells of 2^shift keys, at most one cell long (so two cells at most).
inline std::vector<KeyBox> randomKeys(std::mt19937& rng, std::size_t n, unsigned shift, std::array<unsigned, 3> dims,
                               int kind) {
  const std::uint32_t cell = 1u << shift;
  std::vector<KeyBox> v(n);
  std::array<std::uint32_t, 3> at{};
  for (int a = 0; a < 3; ++a) at[a] = below(rng, dims[a]) * cell;
  for (auto& b : v)
    for (int a = 0; a < 3; ++a) {
      const std::uint32_t top = dims[a] * cell - 1;
      if (kind == 0) {  // anywhere
        b.min[a] = below(rng, top + 1);
        b.max[a] = std::min(top, b.min[a] + below(rng, cell));
      } else if (kind == 1 && dims[a] > 1 && cell > 1) {  // straddles a cell boundary
        const std::uint32_t edge = (1 + below(rng, dims[a] - 1)) * cell;
        b.min[a] = edge - 1 - below(rng, cell - 1), b.max[a] = edge + below(rng, cell - 1);
      } else if (kind == 2) {  // all in one cell
        b.min[a] = at[a] + below(rng, cell);
        b.max[a] = std::min(at[a] + cell - 1, b.min[a] + below(rng, cell));
      } else {  // zero extent on cell boundaries
        b.min[a] = b.max[a] = std::min(top, below(rng, dims[a]) * cell + (below(rng, 2) ? cell - 1 : 0));
      }
    }
  return v;
}

}  // namespace bpaccel::testing
