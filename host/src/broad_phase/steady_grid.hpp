#pragma once
// The grid of a scene that moves little from frame to frame, kept so that one
// pass over the boxes both surveys them and writes their keys.

#include <optional>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "binning_grid.hpp"

namespace bpaccel {

/// A fresh grid follows the boxes' bounds and longest extents, which move a
/// little every frame, so its keys cannot be written before the survey ends.
/// The last frame's grid can: it is kept while the boxes reach at most 1/16
/// of a cell beyond it (their keys clamped into its end cells) and its cells
/// are at most 1/16 longer than a fresh grid's. Any grid keeps the pairs exact (the keys round outwards, and every
/// pair the device reports is rechecked on the float boxes): the rule keeps
/// only the device's cells as small as a fresh grid's.
class SteadyGrid {
 public:
  struct Frame {
    ExtentSurvey survey;  // surveyExtents' for this frame: a common one (allWithin)
    KeyGrid grid;         // the kept grid, or a fresh one when the kept no longer serves
    bool keysDone;        // keys hold every box's keys on `grid`, and all fit the cells
  };
  /// For a frame of boxes that is common by the kept grid's guess (surveyCommonOnGrid), its survey and grid,
  /// and its keys in `keys` (resized to the boxes) when the kept grid serves. nullopt when there is no kept
  /// grid or the frame is not such a common frame: surveyExtents then decides.
  std::optional<Frame> survey(const BinningParams& p, std::span<const Aabb> boxes, std::vector<KeyBox>& keys) const;
  /// The grid a common frame of one device frame used, surveyed as `survey`: the next frame's guess.
  void keep(const KeyGrid& grid, const ExtentSurvey& survey) { kept_ = Kept{grid, survey.topFloor}; }
  void forget() { kept_.reset(); }

  /// Whether `kept` still serves boxes within `bounds`, for which gridFor gave `fresh`.
  static bool serves(const KeyGrid& kept, const KeyGrid& fresh, const AxisBounds& bounds);

 private:
  struct Kept {
    KeyGrid grid;
    std::array<double, 3> topFloor;
  };
  std::optional<Kept> kept_;
};

}  // namespace bpaccel
