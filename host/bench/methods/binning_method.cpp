#include "binning_method.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>

#include "model/fpga_report.hpp"
#include "bpaccel_shell.h"

namespace bpaccel {

std::size_t frameBoxBytes(unsigned keyWidth) { return keyWidth <= 16 ? 12 : 24; }
std::size_t framePairBytes(unsigned indexWidth) { return indexWidth <= 16 ? 4 : 8; }

BinningFrameModel modelBinningFrame(const BinningFrameStats& stats, const BinningParams& params,
                                    const DeviceProfile& profile) {
  const double clock = profile.part.clockHz.value, bandwidth = profile.link.effectiveBytesPerSecond.value;
  const double frames = static_cast<double>(stats.frames + stats.retries);
  const double boxBytes = static_cast<double>(stats.boxesSent * frameBoxBytes(params.keyWidth)) +
                          frames * kFrameHeaderBytes;
  const double backBytes = static_cast<double>(stats.devicePairs * framePairBytes(params.indexWidth())) +
                           frames * kFrameTrailerBytes;
  BinningFrameModel m;
  m.deviceSeconds = static_cast<double>(stats.deviceCycles) / clock;
  // The intake takes the boxes as they arrive: the link adds only what it is slower than the intake.
  const double intakeSeconds = static_cast<double>(stats.phases.intake) / clock;
  m.transferSeconds = 2 * frames * profile.link.latencySeconds.value +
                      std::max(0.0, boxBytes / bandwidth - intakeSeconds) + backBytes / bandwidth;
  return m;
}

ShellFormat binningShellFormat(const BinningParams& params) {
  ShellFormat f;
  f.wordsPerBeat = 8;
  f.keyWidth = params.keyWidth;
  f.boxWords = static_cast<unsigned>(frameBoxBytes(params.keyWidth) / 4);  // the link model's sizes, in words
  f.indexWidth = params.indexWidth();
  f.indexWords = static_cast<unsigned>(framePairBytes(params.indexWidth()) / 4);
  f.lanes = params.lanes();
  f.capacity = params.boxCapacity;
  f.bipartite = false;
  f.cellBits = params.cellBits;
  return f;
}

void ModelledFrameCard::record() {
  kept_.clear();
  next_ = 0;
  replaying_ = false;
}

void ModelledFrameCard::replay() {
  next_ = 0;
  replaying_ = true;
}

std::uint64_t ModelledFrameCard::sampleOf(const FrameCommand& command) {
  const std::size_t n = command.boxes.size(), step = std::max<std::size_t>(1, n / 64);
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (std::size_t k = 0; k < n; k += step)
    for (int a = 0; a < 3; ++a) {
      h = (h ^ command.boxes[k].min[a]) * 0x100000001b3ull;
      h = (h ^ command.boxes[k].max[a]) * 0x100000001b3ull;
    }
  return h;
}

FrameReply ModelledFrameCard::runFrame(const FrameCommand& command) {
  encodeFrame(format_, command.boxes, FrameGrid{command.shift, command.dims}, packet_);  // the driver's
  const auto t0 = std::chrono::steady_clock::now();
  const Kept* kept = nullptr;
  if (replaying_) {
    if (next_ >= kept_.size() || kept_[next_].n != command.count() || kept_[next_].shift != command.shift ||
        kept_[next_].dims != command.dims || kept_[next_].sample != sampleOf(command))
      throw std::logic_error(fmt::format("modelled card: command {} of the replay is not the one recorded", next_));
    kept = &kept_[next_++];
  } else {
    Kept k{command.count(), command.shift, command.dims, sampleOf(command), inner_.runFrame(command), {}};
    // The reply's words as the card sends them: a record a pair, whole beats, then the trailer.
    for (const auto& [i, j] : k.reply.pairs)
      if (format_.indexWords == 1) k.words.push_back(j << 16 | i);
      else k.words.push_back(i), k.words.push_back(j);
    k.words.resize(format_.paddedWords(k.words.size()) + BPACCEL_SHELL_TRAILER_WORDS);
    kept_.push_back(std::move(k));
    kept = &kept_.back();
  }
  FrameReply r = kept->reply;
  r.pairs.clear();
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (r.error != FrameError::None) return r;  // the driver reads an error trailer's code, never its records
  Trailer trailer;
  trailer.records = static_cast<std::uint32_t>(kept->reply.pairs.size());
  trailer.pairs = kept->reply.pairs.size();
  decodeFrameReply(format_, kept->words, trailer, command.count(), r.pairs);  // the driver's
  return r;
}

BinningMethod::BinningMethod(const BinningParams& params, DeviceProfile profile)
    : device_(params), timed_(device_), frame_(timed_), profile_(std::move(profile)) {}

void BinningMethod::update(std::span<const Aabb> boxes) {
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  // The recording pass: the model stands in for the card; none of it is host work.
  const auto r0 = Clock::now();
  const SteadyGrid kept = frame_.steadyGrid();  // the last frame's grid, for the timed pass too
  timed_.record();
  frame_.findPairs(boxes, pairs_);
  const auto r1 = Clock::now();
  frame_.steadyGrid() = kept;
  timed_.replay();
  timed_.seconds = 0;
  const auto t0 = Clock::now();
  frame_.plan(boxes);
  const auto t1 = Clock::now();
  frame_.send();
  const auto t2 = Clock::now();
  frame_.collect(pairs_);
  const auto t3 = Clock::now();
  simulationSeconds_ = seconds(r0, r1) + timed_.seconds;
  planSeconds_ = seconds(t0, t1), driverSeconds_ = seconds(t1, t2) - timed_.seconds, collectSeconds_ = seconds(t2, t3);
}

FrameTime BinningMethod::frameTime(double measuredSeconds) const {
  const BinningFrameStats& s = frame_.stats();
  const BinningFrameModel m = modelBinningFrame(s, device_.params(), profile_);
  ModelledParts p;
  p.hostSeconds = measuredSeconds - simulationSeconds_;
  p.deviceSeconds = m.deviceSeconds;
  p.transferSeconds = m.transferSeconds;
  p.stats.runs = p.stats.batches = s.frames + s.retries;
  p.stats.cycles = s.deviceCycles;
  p.stats.issueCycles = s.issueCycles;
  p.stats.hits = s.devicePairs;
  p.stats.boxesSent = s.boxesSent;
  return {p.hostSeconds + p.deviceSeconds + p.transferSeconds, p};
}

DeviceProfile binningProfile(const DeviceProfile& profile, const BinningParams& params, const std::string& fpgaDir) {
  ProfileInputs in;
  in.device = {static_cast<int>(params.lanes()), "binning", static_cast<int>(params.keyWidth)};
  in.fpgaDir = fpgaDir;
  in.lfe5uReport = (std::filesystem::path(fpgaDir) /
                    std::filesystem::path(fpgaReportPath(in.device.m, in.device.arch, in.device.keyWidth)).filename())
                       .string();
  ProfiledValue standIn = profile.part.clockHz;  // measured or not, it is another design's
  if (standIn.provenance == Provenance::Measured) standIn.provenance = Provenance::StandIn;
  standIn.source = "stand-in: the stream device's clock, " + standIn.source;
  DeviceProfile p = profile;
  if (profile.name == "ecp5-5g") {
    p.part = resolvePart(profile.part.name, profile.part.speedGrade, fiveGReportOrPattern(in), in.device, standIn);
    return p;
  }
  const DeviceClock c = clockFromFpgaReport(in.lfe5uReport, in.device.m, in.device.arch, in.device.keyWidth);
  if (c.measured) {
    p.part.clockHz = {c.hz, Provenance::StandIn, "stand-in: the binning design's LFE5U-85F speed 6 clock, " + c.source};
  } else {
    p.part.clockHz = standIn;
    p.part.clockHz.source = "no binning design clock (" + c.source + "); " + standIn.source;
  }
  return p;
}

std::vector<MethodSpec> binningMethods(const BinningParams& params, const std::vector<DeviceProfile>& profiles) {
  std::vector<MethodSpec> specs;
  for (const DeviceProfile& stream : profiles) {
    const DeviceProfile profile = binningProfile(stream, params);
    MethodSpec s;
    s.name = "accelerator binning on " + profile.name;
    s.kind = MethodKind::Accelerator;
    s.library = "bpaccel";
    s.partition = "binning";
    s.profile = profile.toJson();
    s.make = [params, profile](const SceneStart&) { return std::make_unique<BinningMethod>(params, profile); };
    specs.push_back(std::move(s));
  }
  return specs;
}

}  // namespace bpaccel
