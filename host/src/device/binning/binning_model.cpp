#include "binning_model.hpp"

#include "binning_timeline.hpp"

namespace bpaccel {

BinningModel::BinningModel(const BinningParams& params, const binning::ScheduleFaults& faults)
    : params_(params), faults_(faults) {
  params_.check();
}

FrameReply BinningModel::runFrame(const FrameCommand& command) {
  const binning::Binned binned = binning::bin(params_, command);
  std::vector<binning::GroupSchedule> schedules;
  if (binned.ok()) {
    schedules.reserve(binned.groups.size());
    for (const auto& entries : binned.groups) schedules.push_back(binning::scheduleGroup(params_, command, entries, faults_));
  }
  return binning::playFrame(params_, command, binned, schedules).reply;
}

}  // namespace bpaccel
