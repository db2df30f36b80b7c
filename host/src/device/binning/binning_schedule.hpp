#pragma once
// What the binning device does with a frame, without its timing: the entries
// each box makes in which group and order, the frame's error, and each
// group's schedule (which pair each lane tests in each schedule cycle, and
// which of them it reports under the exactly-once rule).

#include <array>
#include <cstdint>
#include <vector>

#include "frame_device.hpp"

namespace bpaccel::binning {

/// One box's entry in one cell: the cell's global coordinates and, per axis
/// (bit a), whether the box starts in that cell.
struct Entry {
  std::uint32_t box = 0;
  std::array<unsigned, 3> cell{};
  std::uint8_t starts = 0;
};

/// Each group's entries in the order its memory takes them; with an error,
/// those of the boxes before the erring one.
struct Binned {
  FrameError error = FrameError::None;
  std::uint64_t detail = 0;
  std::vector<std::vector<Entry>> groups;
  bool ok() const { return error == FrameError::None; }
};

/// Bins a frame: each box in stream order puts one entry into the group of
/// each cell it covers (x fastest); the first error in stream order ends it.
Binned bin(const BinningParams& p, const FrameCommand& f);

/// One schedule cycle of a group: a cell's bubble (loads its A registers),
/// or an issue whose reported pairs are hits[hitBegin, hitEnd) (lowest lane first).
struct Op {
  bool bubble = false;
  std::uint32_t hitBegin = 0, hitEnd = 0;
};

/// A group's cells in walk order (their entry counts) and its schedule.
struct GroupSchedule {
  std::vector<std::uint32_t> cellSizes;  // by walk position (x fastest, then y, then z)
  std::vector<Op> ops;
  std::vector<Pair> hits;
};

/// Deliberate bugs, for the tests that prove they are caught; none in a real model.
struct ScheduleFaults {
  bool skipExactlyOnce = false;  // report every overlap in every cell both boxes share
};

/// The group's schedule: for each cell of two or more entries in walk order,
/// one bubble and then the stream schedule on g lanes (block b: lane k of its
/// cycle d compares entries b*g + k and b*g + 1 + d + k). A lane reports
/// (a, b) when the keys overlap and on every axis a or b starts in the cell.
GroupSchedule scheduleGroup(const BinningParams& p, const FrameCommand& f, const std::vector<Entry>& entries,
                            const ScheduleFaults& faults = {});

}  // namespace bpaccel::binning
