#include "binning_frame.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

#include "../core/keys.hpp"
#include "gather.hpp"

namespace bpaccel {
namespace {

Pair ordered(std::uint32_t a, std::uint32_t b) { return a < b ? Pair{a, b} : Pair{b, a}; }

}  // namespace

void BinningFrame::findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out) {
  plan(boxes);
  send();
  collect(out);
}

void BinningFrame::plan(std::span<const Aabb> boxes) {
  const BinningParams& p = device_.params();
  // A scene of one device frame tries the last frame's grid first: one pass then surveys and writes the keys.
  const auto steady = boxes.size() <= p.boxCapacity ? steady_.survey(p, boxes, steadyKeys_) : std::nullopt;
  const ExtentSurvey survey = steady ? steady->survey : surveyExtents(p, boxes);  // checks the boxes
  boxes_ = boxes;
  stats_ = {};
  for (PlannedFrame& f : frames_) spare_.push_back(std::move(f));  // their buffers, for this frame's
  frames_.clear();
  replies_.clear();
  hostPairs_.clear();
  longIds_.clear();
  isLong_.assign(boxes.size(), 0);
  cellEdge_ = survey.cellEdge;
  PlannedFrame whole = takeSpare();
  AxisBounds bounds = survey.bounds;
  if (survey.allWithin) {
    whole.ids.resize(boxes.size());
    std::iota(whole.ids.begin(), whole.ids.end(), 0u);
  } else {
    bounds = keepFitting(whole.ids);
  }
  if (whole.ids.size() <= p.boxCapacity) {  // the common frame: one device frame
    // The steady pass's grid is the kept one, or gridFor these bounds when the kept no longer serves.
    whole.grid = steady ? steady->grid : gridFor(p, bounds, cellEdge_);
    whole.region = Region{};
    const bool keysDone = steady && steady->keysDone;
    if (keysDone) std::swap(whole.keys, steadyKeys_), stats_.onePass = true;
    frames_.push_back(std::move(whole));
    if (!keysDone) fillKeys(frames_.back());
    if (survey.allWithin) steady_.keep(frames_.back().grid, survey);
    else steady_.forget();
    return;
  }
  steady_.forget();
  planRegions(whole.ids, bounds);
  spare_.push_back(std::move(whole));
}

AxisBounds BinningFrame::keepFitting(std::vector<std::uint32_t>& ids) {
  // A box fits when its extent, widened by the keys' rounding as surveyExtents widens, is within the cell
  // edge (fitsCells on its keys decides; this sends the longer boxes to the host's path early). Most boxes
  // are well within: a multiplication tells, and the division runs for the few near the edge.
  const double keys = std::ldexp(1.0, static_cast<int>(device_.params().maxShift()));
  std::array<double, 3> within{};
  for (int a = 0; a < 3; ++a) within[a] = cellEdge_[a] * (keys - 8) / keys;
  const auto fits = [&](double e, int a) { return e <= within[a] || e * keys / (keys - 4) <= cellEdge_[a]; };
  ids.clear();
  AxisBounds bounds;
  for (std::uint32_t i = 0; i < boxes_.size(); ++i) {
    const Aabb& b = boxes_[i];
    if (fits(double{b.max[0]} - double{b.min[0]}, 0) && fits(double{b.max[1]} - double{b.min[1]}, 1) &&
        fits(double{b.max[2]} - double{b.min[2]}, 2)) {
      ids.push_back(i);
      bounds.add(b);
    } else {
      longIds_.push_back(i), isLong_[i] = 1;
    }
  }
  return bounds;
}

void BinningFrame::planRegions(std::span<const std::uint32_t> ids, const AxisBounds& bounds) {
  // About 90 % of the capacity a region, in a grid over the two longest axes, as square as the scene's
  // extent on them allows: a thin slab spans few cells across, leaving lane groups idle while the
  // memories of the others overflow.
  const BinningParams& p = device_.params();
  const std::size_t regions = (ids.size() + p.boxCapacity * 9 / 10 - 1) / (p.boxCapacity * 9 / 10);
  std::array<int, 3> axes{0, 1, 2};
  const auto range = [&](int a) { return bounds.hi[a] - bounds.lo[a]; };
  std::sort(axes.begin(), axes.end(), [&](int x, int y) { return range(x) > range(y); });
  const double ratio = std::min(range(axes[0]) / std::max(range(axes[1]), 1e-300), 1e6);
  const auto first = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(regions) * ratio))), 1, regions);
  const std::size_t second = (regions + first - 1) / first;
  for (auto& [slabIds, slab] : cutter_.cut(boxes_, ids, Region{}, axes[0], first))
    for (auto& [partIds, part] : cutter_.cut(boxes_, slabIds, slab, axes[1], second))
      if (!partIds.empty()) frames_.push_back(makeFrame(std::move(partIds), part));
}

PlannedFrame BinningFrame::takeSpare() {
  if (spare_.empty()) return {};
  PlannedFrame f = std::move(spare_.back());
  spare_.pop_back();
  return f;
}

PlannedFrame BinningFrame::makeFrame(std::vector<std::uint32_t> ids, const Region& region) {
  PlannedFrame f = takeSpare();
  f.grid = pickGrid(device_.params(), boxes_, ids, cellEdge_);
  f.ids = std::move(ids);
  f.region = region;
  fillKeys(f);
  return f;
}

void BinningFrame::fillKeys(PlannedFrame& f) {
  f.keys.resize(f.ids.size());
  if (quantizeAll(f.grid, boxes_, f.ids, f.keys)) [[likely]]
    return;
  // By construction no box spans more than two cells; should rounding ever say otherwise, the box is the host's.
  std::size_t n = 0;
  for (std::size_t k = 0; k < f.ids.size(); ++k) {
    if (fitsCells(f.grid, f.keys[k])) {
      f.ids[n] = f.ids[k];
      f.keys[n++] = f.keys[k];
    } else if (!isLong_[f.ids[k]]) {
      isLong_[f.ids[k]] = 1;
      longIds_.push_back(f.ids[k]);
    }
  }
  f.ids.resize(n);
  f.keys.resize(n);
}

void BinningFrame::send() {
  std::vector<PlannedFrame> todo(std::make_move_iterator(frames_.begin()), std::make_move_iterator(frames_.end()));
  frames_.clear();
  while (!todo.empty()) {
    PlannedFrame f = std::move(todo.back());
    todo.pop_back();
    FrameCommand c{f.keys, f.grid.shift, f.grid.dims, std::nullopt};
    FrameReply r = device_.runFrame(c);
    stats_.deviceCycles += r.cycles;
    stats_.boxesSent += f.ids.size();
    if (r.error == FrameError::GroupOverflow || r.error == FrameError::CountOverCapacity) {
      stats_.retries += 1;
      if (!split(f, todo)) hostPairs(f);
      continue;
    }
    if (r.error != FrameError::None)
      throw std::logic_error(fmt::format("binning frame: the device refused a frame of the host's with {} at box {}",
                                         frameErrorName(r.error), r.detail));
    stats_.frames += 1;
    stats_.devicePairs += r.pairs.size();
    stats_.issueCycles += r.issueCycles;
    stats_.phases.intake += r.phases.intake, stats_.phases.prefix += r.phases.prefix;
    stats_.phases.sort += r.phases.sort, stats_.phases.compute += r.phases.compute;
    stats_.phases.drain += r.phases.drain;
    frames_.push_back(std::move(f));
    replies_.push_back(std::move(r));
  }
}

void BinningFrame::decode(const PlannedFrame& f, const FrameReply& r, std::vector<Pair>& out) {
  const bool bounded = f.region.bounded();
  // The pairs come in the device's order, so the boxes are read at random: each read is asked for ahead.
  const std::size_t n = f.ids.size();
  for (std::size_t k = 0; k < r.pairs.size(); ++k) {
    if (k + kGatherAhead < r.pairs.size()) {
      const auto [pi, pj] = r.pairs[k + kGatherAhead];
      if (pi < n && pj < n) __builtin_prefetch(&boxes_[f.ids[pi]]), __builtin_prefetch(&boxes_[f.ids[pj]]);
    }
    const auto [li, lj] = r.pairs[k];
    const std::uint32_t i = f.ids.at(li), j = f.ids.at(lj);
    const Aabb &a = boxes_[i], &b = boxes_[j];
    if (!overlaps(a, b)) {
      stats_.falsePositives += 1;
      continue;
    }
    if (bounded && !f.region.owns(a, b)) {
      stats_.boundaryDrops += 1;
      continue;
    }
    out.push_back(ordered(i, j));
  }
}

bool BinningFrame::split(const PlannedFrame& f, std::vector<PlannedFrame>& todo) {
  // On the axis where the frame's grid is longest first; another where all mins are equal there.
  std::array<int, 3> axes{0, 1, 2};
  const auto length = [&](int a) { return f.grid.unit[a] * f.grid.dims[a]; };
  std::sort(axes.begin(), axes.end(), [&](int x, int y) { return length(x) > length(y); });
  for (int axis : axes) {
    auto halves = cutter_.cut(boxes_, f.ids, f.region, axis, 2);
    // A cut helps when each half holds fewer boxes than the frame (all mins equal on the axis: none does).
    const auto smaller = [&](const auto& half) { return !half.first.empty() && half.first.size() < f.ids.size(); };
    if (halves.size() < 2 || !std::all_of(halves.begin(), halves.end(), smaller)) continue;
    for (auto& [ids, region] : halves) todo.push_back(makeFrame(std::move(ids), region));
    return true;
  }
  return false;
}

void BinningFrame::hostPairs(const PlannedFrame& f) {
  // A region the device cannot hold and that cannot be cut: all its pairs on the host, its ownership rule kept.
  for (std::size_t x = 0; x < f.ids.size(); ++x)
    for (std::size_t y = x + 1; y < f.ids.size(); ++y) {
      const Aabb &a = boxes_[f.ids[x]], &b = boxes_[f.ids[y]];
      if (overlaps(a, b) && f.region.owns(a, b)) hostPairs_.push_back(ordered(f.ids[x], f.ids[y]));
    }
}

void BinningFrame::longBoxPairs(std::vector<Pair>& out) const {
  for (std::uint32_t l : longIds_)
    for (std::uint32_t i = 0; i < boxes_.size(); ++i)
      if (i != l && (!isLong_[i] || i > l) && overlaps(boxes_[l], boxes_[i])) out.push_back(ordered(l, i));
}

void BinningFrame::collect(std::vector<Pair>& out) {
  out.clear();
  for (std::size_t k = 0; k < frames_.size(); ++k) decode(frames_[k], replies_[k], out);
  out.insert(out.end(), hostPairs_.begin(), hostPairs_.end());
  longBoxPairs(out);
  stats_.hostBoxes = longIds_.size();
}

}  // namespace bpaccel
