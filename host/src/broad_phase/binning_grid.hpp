#pragma once
// The host's half of a binning frame: float boxes to the device's narrow keys
// on a grid the host picks, rounding outwards so no overlap is lost.

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "../device/binning/binning_params.hpp"

namespace bpaccel {

/// One frame's grid: per axis an origin and a key unit (float units per key
/// step), the shift s and the cells per axis. A cell is 2^s keys wide.
struct KeyGrid {
  std::array<double, 3> origin{};
  std::array<double, 3> unit{1, 1, 1};
  std::array<double, 3> scale{1, 1, 1};  // 1 / unit
  std::array<double, 3> top{};           // the highest key: dims * 2^shift - 1, within the key width
  unsigned shift = 0;
  std::array<unsigned, 3> dims{1, 1, 1};
};

/// Per axis the least min and the greatest max of the boxes added (for none, lo above hi).
struct AxisBounds {
  std::array<double, 3> lo{HUGE_VAL, HUGE_VAL, HUGE_VAL};
  std::array<double, 3> hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  void add(const Aabb& b);
};

/// The grid for boxes within `bounds`: s = the device's largest shift (the
/// finest keys), and per axis the cell edge max(range / 2^cellBits,
/// `cellEdge`), so a box no longer than that edge spans at most two cells.
KeyGrid gridFor(const BinningParams& p, const AxisBounds& bounds, const std::array<double, 3>& cellEdge);

/// gridFor the bounds of `ids` (boxes of `boxes`).
KeyGrid pickGrid(const BinningParams& p, std::span<const Aabb> boxes, std::span<const std::uint32_t> ids,
                 const std::array<double, 3>& cellEdge);

/// Box b's keys on `grid`: min rounded down, max up, clamped to the grid.
/// Each step (float to double, subtract, multiply by the positive scale,
/// clamp, round down or up) is monotone, so a <= b as floats gives key(a) <= key(b): overlapping boxes
/// keep overlapping, and the device reports a superset of the pairs.
KeyBox quantize(const KeyGrid& grid, const Aabb& b);

/// keys[k] = quantize(grid, boxes[ids[k]]) for every k, bit for bit, with
/// vector instructions where the CPU has them (keys is ids.size() long).
/// Returns whether every box's keys fit the cells (fitsCells).
bool quantizeAll(const KeyGrid& grid, std::span<const Aabb> boxes, std::span<const std::uint32_t> ids,
                 std::span<KeyBox> keys);

/// Whether `key` covers at most two cells per axis (what the device takes).
bool fitsCells(const KeyGrid& grid, const KeyBox& key);

/// What the host reads of a frame's boxes before it picks a grid, in one pass.
struct ExtentSurvey {
  /// Per axis, the cell edge the grid must reach, with a margin for the keys'
  /// rounding: the longest finite extent, unless it is above twice the extent
  /// all but n / 256 boxes stay within (outliers); then twice that extent, and
  /// the longer boxes (at most n / 256 an axis) take the host's exact path.
  std::array<double, 3> cellEdge{};
  AxisBounds bounds;       // of every box
  bool allWithin = false;  // no outlier and no infinite extent: every box is within the cell edge
  /// Per axis, the floor of the longest finite extent's binary exponent bucket and the one below (its top
  /// buckets, which decide whether any extent is an outlier): what a one-pass survey of the next frame guesses.
  std::array<double, 3> topFloor{};
};
/// The survey of `boxes`, which it checks as checkBoxes does (in its first
/// pass where it can): throws InputError for the first bad box.
ExtentSurvey surveyExtents(const BinningParams& p, std::span<const Aabb> boxes);

/// A common frame's survey (every box checked, every extent finite, no outlier: `allWithin`) and its keys on a
/// grid chosen before, from one pass over the boxes.
struct CommonPass {
  ExtentSurvey survey;
  bool keysFit = false;  // every box's keys on the grid fit two cells (fitsCells)
};
/// surveyExtents and quantizeAll in one pass over `boxes` (keys[k] for boxes[k]; keys is boxes.size() long),
/// for a frame whose longest extents have the top floors guessed (the last frame's): the survey is
/// surveyExtents' and the keys quantize's, bit for bit. nullopt when the frame is not such a common frame (a
/// box to check, an infinite extent, another floor, an outlier), when the CPU has no AVX2, or for fewer than two
/// boxes: surveyExtents' path then decides, and keys holds nothing of use.
std::optional<CommonPass> surveyCommonOnGrid(const BinningParams& p, std::span<const Aabb> boxes, const KeyGrid& grid,
                                             const std::array<double, 3>& guessedFloor, std::span<KeyBox> keys);

}  // namespace bpaccel
