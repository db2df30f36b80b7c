#pragma once
// The cycle-exact C++ model of the binning device behind its FRAME command.

#include <string>

#include "binning_schedule.hpp"
#include "frame_device.hpp"

namespace bpaccel {

/// The binning device at software speed: the same entries, pairs (in the
/// same order), errors and cycles as bpaccel.binning.BinningCycleModel, which
/// the RTL matches cycle by cycle, with a consumer that never stalls and a
/// host that offers intakeBoxes boxes every cycle (host/tests/device/binning
/// checks it against vectors the Scala model wrote).
class BinningModel final : public FrameDevice {
 public:
  /// Throws std::invalid_argument for parameters no generator builds.
  explicit BinningModel(const BinningParams& params, const binning::ScheduleFaults& faults = {});
  std::string name() const override { return "binning-model"; }
  const BinningParams& params() const override { return params_; }
  FrameReply runFrame(const FrameCommand& command) override;

 private:
  BinningParams params_;
  binning::ScheduleFaults faults_;
};

}  // namespace bpaccel
