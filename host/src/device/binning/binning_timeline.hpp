#pragma once
// The binning device's timing: the frame played cycle by cycle, queue by
// queue, as bpaccel.binning.BinningCycleModel plays it (which the RTL matches
// cycle by cycle on Verilator), with a consumer that is always ready and a
// host that offers a beat of intakeBoxes boxes every cycle.

#include <vector>

#include "binning_schedule.hpp"

namespace bpaccel::binning {

/// A frame's reply and when each group's phases began (cycle numbers; empty with an error).
struct PlayedFrame {
  FrameReply reply;
  std::uint64_t intakeDone = 0;  // T: the last cycle of the intake
  std::vector<std::uint64_t> sortStart, computeStart, groupDone;
};

/// The reply of a frame already binned and scheduled (`schedules`: one per
/// group, empty when `binned` has an error): its pairs in the order the
/// output sends them, its cycles and phases. Throws std::logic_error if the
/// play does not end within `maxCycles` (a bug, never a frame's fault).
PlayedFrame playFrame(const BinningParams& p, const FrameCommand& f, const Binned& binned,
                     const std::vector<GroupSchedule>& schedules, std::uint64_t maxCycles = 50'000'000);

}  // namespace bpaccel::binning
