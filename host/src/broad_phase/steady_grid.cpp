#include "steady_grid.hpp"

#include <cmath>

namespace bpaccel {

std::optional<SteadyGrid::Frame> SteadyGrid::survey(const BinningParams& p, std::span<const Aabb> boxes,
                                                    std::vector<KeyBox>& keys) const {
  if (!kept_) return std::nullopt;
  keys.resize(boxes.size());
  const std::optional<CommonPass> pass = surveyCommonOnGrid(p, boxes, kept_->grid, kept_->topFloor, keys);
  if (!pass) return std::nullopt;
  const KeyGrid fresh = gridFor(p, pass->survey.bounds, pass->survey.cellEdge);
  if (pass->keysFit && serves(kept_->grid, fresh, pass->survey.bounds)) return Frame{pass->survey, kept_->grid, true};
  return Frame{pass->survey, fresh, false};
}

bool SteadyGrid::serves(const KeyGrid& kept, const KeyGrid& fresh, const AxisBounds& bounds) {
  if (kept.shift != fresh.shift) return false;
  for (int a = 0; a < 3; ++a) {
    // Keys run from 0 at the origin to top + 1 at the grid's far end (on a fresh grid, the boxes' least min
    // and greatest max). A box beyond either end has its keys clamped into the end cell, which stays exact
    // (clamping is monotone) and costs nothing while the boxes reach at most 1/16 of a cell beyond it.
    const double end = kept.origin[a] + (kept.top[a] + 1) * kept.unit[a];
    const double slack = std::ldexp(kept.unit[a], static_cast<int>(kept.shift)) / 16;
    const bool covers = kept.origin[a] - slack <= bounds.lo[a] && bounds.hi[a] <= end + slack;
    if (!covers || kept.unit[a] > fresh.unit[a] * (17.0 / 16.0)) return false;
  }
  return true;
}

}  // namespace bpaccel
