#pragma once
// Regions of space and the cut of a set of boxes into slabs of them: the
// binning device's host path sends a scene above the device's capacity as
// regions, each box to every region it meets.

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "../core/types.hpp"

namespace bpaccel {

/// A part of space, [lo, hi) on each axis (unbounded: the infinities). It
/// owns the pairs whose intersection's low corner (the greater min on each
/// axis) lies in it: regions that tile space own each pair once.
struct Region {
  std::array<double, 3> lo{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  std::array<double, 3> hi{HUGE_VAL, HUGE_VAL, HUGE_VAL};
  bool bounded() const;
  /// Whether the region owns the pair of overlapping boxes a, b.
  bool owns(const Aabb& a, const Aabb& b) const;
};

/// A slab: the ids of the boxes that meet it, and its region.
using Slab = std::pair<std::vector<std::uint32_t>, Region>;

/// Cuts boxes into slabs along an axis; keeps its buffers from one cut to the next.
class SlabCutter {
 public:
  /// Cuts `outer` on `axis` into up to `parts` slabs at quantiles of the mins of `ids` (boxes of `boxes`):
  /// their boxes, each in every slab it meets, and their regions.
  std::vector<Slab> cut(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids, const Region& outer, int axis,
                        std::size_t parts);

 private:
  static constexpr std::size_t kBins = 4096;
  /// kBins equal bins from `least` on, each `width` wide.
  struct Histogram {
    double least, width;
    double edge(std::size_t bin) const { return least + static_cast<double>(bin) * width; }
  };
  /// outer's ends on the axis (lo, hi) and the cuts between, from the mins' histogram; fills bins_.
  std::vector<double> quantileCuts(const Histogram& bins, double most, double lo, double hi, std::size_t parts);
  /// The boxes, each into every slab between `cuts` it meets.
  std::vector<Slab> assign(std::span<const std::uint32_t> ids, const Region& outer, int axis,
                           const std::vector<double>& cuts, const Histogram& bins);

  std::vector<double> mins_;         // the mins of the boxes on the axis
  std::vector<double> maxes_;        // and their maxes
  std::vector<std::uint16_t> bins_;  // their histogram bins
  std::vector<std::pair<std::uint16_t, std::uint16_t>> spans_;  // the slabs each box meets, [first, end)
};

}  // namespace bpaccel
