#include "slab_cutter.hpp"

#include <algorithm>
#include <limits>

#include "gather.hpp"

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

namespace {

// Four running minima and maxima: one pair would make each box wait for the last one's compare.
std::pair<double, double> gatherEnds(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids, int axis,
                                     std::vector<double>& mins, std::vector<double>& maxes) {
  std::array<double, 4> least{HUGE_VAL, HUGE_VAL, HUGE_VAL, HUGE_VAL};
  std::array<double, 4> most{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::size_t k = 0; k < ids.size(); ++k) {
    prefetchAhead(boxes, ids, k);
    const double m = boxes[ids[k]].min[axis];
    mins[k] = m;
    maxes[k] = boxes[ids[k]].max[axis];
    least[k % 4] = std::min(least[k % 4], m);
    most[k % 4] = std::max(most[k % 4], m);
  }
  return {std::min({least[0], least[1], least[2], least[3]}), std::max({most[0], most[1], most[2], most[3]})};
}

}  // namespace

std::vector<Slab> SlabCutter::cut(std::span<const Aabb> boxes, std::span<const std::uint32_t> ids,
                                  const Region& outer, int axis, std::size_t parts) {
  // The ends gathered once, and each min's histogram bin kept: the passes after read them in order.
  mins_.resize(ids.size());
  maxes_.resize(ids.size());
  const auto [least, most] = gatherEnds(boxes, ids, axis, mins_, maxes_);
  const Histogram bins{least, (most - least) / kBins};
  const std::vector<double> cuts = parts > 1 && most > least && std::isfinite(most - least)
                                       ? quantileCuts(bins, most, outer.lo[axis], outer.hi[axis], parts)
                                       : std::vector<double>{outer.lo[axis], outer.hi[axis]};
  return assign(ids, outer, axis, cuts, bins);
}

std::vector<double> SlabCutter::quantileCuts(const Histogram& bins, double most, double lo, double hi,
                                             std::size_t parts) {
  // Near the quantiles k / parts of the mins, at the edges of the histogram's bins (any cut keeps the
  // frame exact, the quantiles only balance the parts).
  bins_.resize(mins_.size());
  std::array<std::uint32_t, kBins + 1> count{};
  for (std::size_t k = 0; k < mins_.size(); ++k) {
    const auto bin =
        static_cast<std::uint16_t>(std::min(kBins, static_cast<std::size_t>((mins_[k] - bins.least) / bins.width)));
    bins_[k] = bin;
    count[bin] += 1;
  }
  std::vector<double> cuts{lo};
  const std::size_t n = mins_.size();
  std::size_t seen = 0, k = 1;
  for (std::size_t bin = 0; bin <= kBins && k < parts; ++bin) {
    seen += count[bin];
    const double edge = bins.edge(bin + 1);  // above every min of bins 0 .. bin
    if (seen >= k * n / parts && edge > cuts.back() && edge < hi && edge <= most) {
      cuts.push_back(edge);
      while (k < parts && seen >= k * n / parts) ++k;
    }
  }
  cuts.push_back(hi);
  return cuts;
}

std::vector<Slab> SlabCutter::assign(std::span<const std::uint32_t> ids, const Region& outer, int axis,
                                     const std::vector<double>& cuts, const Histogram& bins) {
  const std::size_t slabs = cuts.size() - 1;
  // Each box into every slab it meets, from the one holding its min (the last whose cut is at or below it,
  // or the first) on. A bin's slab is a guess that the comparisons with the cuts then make exact: no
  // binary search, and its mispredicted branches, a box. The slabs' sizes are counted first, so the
  // ids are then written with no check of room.
  std::array<std::uint16_t, kBins + 1> guess{};  // slabs <= kBins + 1: the cuts are at bins' edges
  for (std::size_t bin = 0, k = 0; slabs > 1 && bin <= kBins; ++bin) {
    while (k + 1 < slabs && cuts[k + 1] <= bins.edge(bin)) ++k;
    guess[bin] = static_cast<std::uint16_t>(k);
  }
  spans_.resize(ids.size());
  // Slab sizes as a difference array, in four copies: one would make each box's count wait for the last's.
  const std::size_t stride = slabs + 1;
  std::vector<std::size_t> sizes(4 * stride);
  // The inner cuts between two NaNs, which every comparison fails: the loops below stop at the first
  // and last slab with no test of the index, a branch each that the slab's position would make random.
  std::vector<double> inner(cuts);
  inner.front() = inner.back() = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t j = 0; j < ids.size(); ++j) {
    const double m = mins_[j];
    std::size_t k = slabs > 1 ? guess[bins_[j]] : 0;
    while (m < inner[k]) --k;
    while (m >= inner[k + 1]) ++k;
    // A box meets slab [lo, hi) when min < hi and max >= lo: the first slab needs both ends checked,
    // each next one only the max.
    const double max = maxes_[j];
    std::size_t end = k;
    if (m < cuts[k + 1] && max >= cuts[k]) {
      end = k + 1;
      while (max >= inner[end]) ++end;
    }
    spans_[j] = {static_cast<std::uint16_t>(k), static_cast<std::uint16_t>(end)};
    std::size_t* const copy = &sizes[(j % 4) * stride];
    copy[k] += 1;  // slabs k .. end - 1 each get the box
    copy[end] -= 1;
  }
  std::vector<Slab> out(slabs);
  std::vector<std::uint32_t*> to(slabs);
  for (std::size_t k = 0, running = 0; k < slabs; ++k) {
    running += sizes[k] + sizes[stride + k] + sizes[2 * stride + k] + sizes[3 * stride + k];
    out[k].first.resize(running);
    to[k] = out[k].first.data();
    out[k].second = outer;
    out[k].second.lo[axis] = cuts[k], out[k].second.hi[axis] = cuts[k + 1];
  }
  for (std::size_t j = 0; j < ids.size(); ++j)
    for (std::size_t k = spans_[j].first; k < spans_[j].second; ++k) *to[k]++ = ids[j];
  return out;
}

}  // namespace bpaccel
