#pragma once
// The host's path to the binning device: each box sent once as narrow keys,
// the device's global pairs decoded and rechecked with the float boxes.

#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "../core/types.hpp"
#include "../device/binning/frame_device.hpp"
#include "binning_grid.hpp"
#include "slab_cutter.hpp"
#include "steady_grid.hpp"

namespace bpaccel {

/// What the last frame cost, counted as the device and the link would see it.
struct BinningFrameStats {
  std::size_t frames = 0;          // device frames that returned pairs (a region each)
  std::size_t retries = 0;         // frames the device refused for room (then cut in two)
  std::size_t boxesSent = 0;       // boxes over the link, summed over the frames sent
  std::size_t hostBoxes = 0;       // boxes too long for the grid, tested on the host
  std::size_t devicePairs = 0;     // pairs the device sent back
  std::size_t falsePositives = 0;  // of them, dropped by the float recheck (quantization)
  std::size_t boundaryDrops = 0;   // of them, owned by a neighbouring region
  bool onePass = false;            // the survey wrote the keys, on the last frame's grid (SteadyGrid)
  std::uint64_t deviceCycles = 0;  // summed over the frames sent, refused ones too
  std::uint64_t issueCycles = 0;
  FramePhases phases;              // summed over the frames that returned pairs
};

/// One device frame of the plan: the boxes it carries (global ids, in stream
/// order) with their keys, its grid, and the region whose pairs it owns.
struct PlannedFrame {
  std::vector<std::uint32_t> ids;
  std::vector<KeyBox> keys;
  KeyGrid grid;
  Region region;
};

/// Finds every overlapping pair of float boxes exactly once on a FrameDevice:
/// - the grid: s = the largest shift, per axis a cell edge of at least the
///   box extent all but ~n/256 boxes stay within (surveyExtents); boxes longer
///   than that, or infinite, go to the host's exact path (each tested with
///   every box), so the device never sees a box wider than two cells;
/// - the keys: rounded outwards (quantize), so the device's pairs are a
///   superset, and each is rechecked with the float boxes (inclusive, as
///   overlaps() on keys);
/// - regions: a scene above the box capacity is cut into a grid of regions
///   over its two longest axes, at quantiles of the boxes' mins (on the first
///   axis, then within each of its slabs on the second), so that each region
///   spans enough cells on both to use all the device's lane groups; a box
///   meeting several regions goes to each, and a pair is kept only by the
///   region holding its intersection's low corner. A frame the device refuses
///   for room (GROUP_OVERFLOW, COUNT_OVER_CAPACITY) is cut in two and sent
///   again; a region that cannot be cut (all mins equal) is tested on the host.
class BinningFrame {
 public:
  explicit BinningFrame(FrameDevice& device) : device_(device) {}
  /// Appends the pairs (i < j) to `out` (cleared first). Throws InputError for a NaN or inverted box.
  void findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);
  /// The steps of findPairs, for a caller that times them: plan (checks,
  /// grid, keys, regions), send (the frames to the device, and their replies
  /// kept), collect (decode, recheck, the host's exact path). plan's boxes
  /// are read until collect returns: they must stay alive and unchanged.
  void plan(std::span<const Aabb> boxes);
  void send();
  void collect(std::vector<Pair>& out);
  const BinningFrameStats& stats() const { return stats_; }
  const std::vector<PlannedFrame>& frames() const { return frames_; }
  /// The grid kept from frame to frame: a caller that runs one frame twice (the bench's recording pass, then
  /// its timed one) puts it back between them, so that the second plans as the first did.
  SteadyGrid& steadyGrid() { return steady_; }

 private:
  /// The boxes within the cell edge into `ids`, the others to the host's path; returns the bounds of `ids`.
  AxisBounds keepFitting(std::vector<std::uint32_t>& ids);
  /// Cuts the scene's fitting boxes `ids` (within `bounds`) into regions, each a frame of frames_.
  void planRegions(std::span<const std::uint32_t> ids, const AxisBounds& bounds);
  /// A frame of spare_, its buffers' capacity kept from an earlier frame, or a new one.
  PlannedFrame takeSpare();
  /// The frame of boxes `ids` owning `region`, with its grid and keys.
  PlannedFrame makeFrame(std::vector<std::uint32_t> ids, const Region& region);
  /// f's keys on its grid, for its ids; a box whose keys span more than two cells goes to the host's path.
  void fillKeys(PlannedFrame& f);
  /// The frame's global pairs, kept where the float boxes overlap and the slab owns them.
  void decode(const PlannedFrame& f, const FrameReply& r, std::vector<Pair>& out);
  /// Cuts a refused frame's region in two at its boxes' median min on an axis; false if none can be cut.
  bool split(const PlannedFrame& f, std::vector<PlannedFrame>& todo);
  void hostPairs(const PlannedFrame& f);
  void longBoxPairs(std::vector<Pair>& out) const;

  FrameDevice& device_;
  std::span<const Aabb> boxes_;
  std::array<double, 3> cellEdge_{};
  std::vector<PlannedFrame> frames_;
  std::vector<PlannedFrame> spare_;  // frames of earlier calls, whose buffers the next frames reuse
  std::vector<FrameReply> replies_;  // send's, one per frame of frames_ that returned pairs
  std::vector<std::uint32_t> longIds_;
  std::vector<std::uint8_t> isLong_;
  std::vector<Pair> hostPairs_;  // of regions no cut could shrink
  SlabCutter cutter_;
  SteadyGrid steady_;                  // the last common frame's grid, tried first
  std::vector<KeyBox> steadyKeys_;     // its pass's keys, swapped into the frame when the grid serves
  BinningFrameStats stats_;
};

}  // namespace bpaccel
