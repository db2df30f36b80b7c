#include "slab_cutter.hpp"

#include <algorithm>

namespace bpaccel {

bool Region::bounded() const {
  for (int a = 0; a < 3; ++a)
    if (std::isfinite(lo[a]) || std::isfinite(hi[a])) return true;
  return false;
}

bool Region::owns(const Aabb& a, const Aabb& b) const {
  for (int x = 0; x < 3; ++x) {
    const double corner = std::max(a.min[x], b.min[x]);
    if (!(corner >= lo[x] && corner < hi[x])) return false;
  }
  return true;
}

std::vector<Slab> SlabCutter::cut(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids,
                                  const Region& outer, int axis, std::size_t parts) {
  // The mins gathered once, and each one's histogram bin kept: the passes after read them in order.
  mins_.resize(ids.size());
  double least = HUGE_VAL, most = -HUGE_VAL;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const double m = boxes[ids[k]].min[axis];
    mins_[k] = m;
    least = m < least ? m : least;
    most = m > most ? m : most;
  }
  // The cuts: near the quantiles k / parts of the mins, at the edges of a histogram's bins (any cut keeps
  // the frame exact, the quantiles only balance the parts).
  std::vector<double> cuts{outer.lo[axis]};
  constexpr std::size_t kBins = 4096;
  const bool binned = parts > 1 && most > least && std::isfinite(most - least);
  const double width = (most - least) / kBins;
  if (binned) {
    bins_.resize(ids.size());
    std::array<std::uint32_t, kBins + 1> count{};
    for (std::size_t k = 0; k < ids.size(); ++k) {
      const auto bin = static_cast<std::uint16_t>(std::min(kBins, static_cast<std::size_t>((mins_[k] - least) / width)));
      bins_[k] = bin;
      count[bin] += 1;
    }
    std::size_t seen = 0, k = 1;
    for (std::size_t bin = 0; bin <= kBins && k < parts; ++bin) {
      seen += count[bin];
      const double edge = least + static_cast<double>(bin + 1) * width;  // above every min of bins 0 .. bin
      if (seen >= k * ids.size() / parts && edge > cuts.back() && edge < outer.hi[axis] && edge <= most) {
        cuts.push_back(edge);
        while (k < parts && seen >= k * ids.size() / parts) ++k;
      }
    }
  }
  cuts.push_back(outer.hi[axis]);
  const std::size_t slabs = cuts.size() - 1;
  std::vector<Slab> out(slabs);
  for (std::size_t k = 0; k < slabs; ++k) {
    out[k].first.reserve(ids.size() / slabs + ids.size() / 8);  // a share, and room for the boxes across cuts
    out[k].second = outer;
    out[k].second.lo[axis] = cuts[k], out[k].second.hi[axis] = cuts[k + 1];
  }
  // Each box into every slab it meets, from the one holding its min (the last whose cut is at or below it,
  // or the first) on. A bin's slab is a guess that the comparisons with the cuts then make exact: no
  // binary search, and its mispredicted branches, a box.
  std::array<std::uint16_t, kBins + 1> guess{};  // slabs <= kBins + 1: the cuts are at bins' edges
  if (slabs > 1) {
    std::size_t k = 0;
    for (std::size_t bin = 0; bin <= kBins; ++bin) {
      while (k + 1 < slabs && cuts[k + 1] <= least + static_cast<double>(bin) * width) ++k;
      guess[bin] = static_cast<std::uint16_t>(k);
    }
  }
  for (std::size_t j = 0; j < ids.size(); ++j) {
    const double m = mins_[j];
    std::size_t k = slabs > 1 ? guess[bins_[j]] : 0;
    while (k > 0 && m < cuts[k]) --k;
    while (k + 1 < slabs && m >= cuts[k + 1]) ++k;
    const std::uint32_t i = ids[j];
    for (; k < slabs && out[k].second.meets(boxes[i], axis); ++k) out[k].first.push_back(i);
  }
  return out;
}

}  // namespace bpaccel
