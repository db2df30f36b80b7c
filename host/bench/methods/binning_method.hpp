#pragma once
// The binning device as a benchmark method: the host's frame path measured,
// the device's cycles from its cycle-exact C++ model, the link modelled, on a
// named DeviceProfile.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "broad_phase/binning_frame.hpp"
#include "device/binning/binning_model.hpp"
#include "device/rtl/shell/frame_codec.hpp"
#include "model/device_profile.hpp"
#include "timed_method.hpp"

namespace bpaccel {

/// Bytes of one box in a FRAME packet: six keys, a half-word each up to 16 bits, else a word (docs/protocol.md).
std::size_t frameBoxBytes(unsigned keyWidth);
/// Bytes of one pair record in a FRAME reply: one word up to 16-bit indices, else two.
std::size_t framePairBytes(unsigned indexWidth);
/// A FRAME packet's header (4 words) and a reply's trailer (8 words).
inline constexpr std::size_t kFrameHeaderBytes = 16, kFrameTrailerBytes = 32;

/// One frame's modelled link and device time on `profile`, from what the frame sent and got back:
///   device = cycles / clock;
///   link   = 2 latencies per device frame + the boxes' bytes beyond what the
///            intake takes in the same time + the pair records and trailers back.
struct BinningFrameModel {
  double deviceSeconds = 0;
  double transferSeconds = 0;
};
BinningFrameModel modelBinningFrame(const BinningFrameStats& stats, const BinningParams& params,
                                    const DeviceProfile& profile);

/// The shell's packet layout for the binning device `params` on a 256-bit
/// stream (docs/protocol.md): what its driver encodes and decodes.
ShellFormat binningShellFormat(const BinningParams& params);

/// The card as the bench models it, in front of a FrameDevice model. The
/// driver's work on the host runs for real (each frame's FRAME packet
/// encoded, the reply's records decoded); the card's own work is no host
/// work and is timed apart in `seconds`. Two modes:
///   record: each command runs on the model, and its reply (with the words
///           the card would send) is kept;
///   replay: each command gets the next kept reply, after a check that it is
///           the command recorded (n, grid, a sample of its keys).
/// A frame replayed runs the host's steps with no simulation between them:
/// a real card does not evict the host's caches while it works, the model
/// would (the decode rereads every pair's boxes).
class ModelledFrameCard final : public FrameDevice {
 public:
  explicit ModelledFrameCard(FrameDevice& inner) : inner_(inner), format_(binningShellFormat(inner.params())) {}
  std::string name() const override { return inner_.name(); }
  const BinningParams& params() const override { return inner_.params(); }
  FrameReply runFrame(const FrameCommand& command) override;
  /// Forgets the kept replies and records the next commands' replies.
  void record();
  /// Replays the kept replies from the first; throws std::logic_error from runFrame for a command that differs.
  void replay();
  double seconds = 0;

 private:
  struct Kept {
    std::size_t n = 0;
    unsigned shift = 0;
    std::array<unsigned, 3> dims{};
    std::uint64_t sample = 0;  // a hash of up to 64 of the command's boxes
    FrameReply reply;
    std::vector<std::uint32_t> words;
  };
  static std::uint64_t sampleOf(const FrameCommand& command);

  FrameDevice& inner_;
  ShellFormat format_;
  std::vector<std::uint32_t> packet_;
  std::vector<Kept> kept_;
  std::size_t next_ = 0;
  bool replaying_ = false;
};

/// "accelerator binning on <profile>": BinningFrame on a BinningModel, each
/// update twice: once with the card recording (the model's replies), then
/// with it replaying them while the host's steps are timed. Host = the
/// measured update minus the recording pass and the card's own time in the
/// replay (the host's own work between commands, retries too, counts).
class BinningMethod final : public TimedMethod {
 public:
  BinningMethod(const BinningParams& params, DeviceProfile profile);
  void update(std::span<const Aabb> boxes) override;
  void pairs(std::vector<Pair>& out) override { out = pairs_; }
  FrameTime frameTime(double measuredSeconds) const override;
  const BinningFrameStats& stats() const { return frame_.stats(); }
  const BinningFrame& frame() const { return frame_; }
  /// The last update's measured host parts: plan (checks, grid, keys, regions), the driver's (the packets
  /// encoded, the replies' records decoded, refused frames cut again) and collect (decode, recheck).
  double planSeconds() const { return planSeconds_; }
  double driverSeconds() const { return driverSeconds_; }
  double collectSeconds() const { return collectSeconds_; }

 private:
  BinningModel device_;
  ModelledFrameCard timed_;
  BinningFrame frame_;
  DeviceProfile profile_;
  double simulationSeconds_ = 0, planSeconds_ = 0, driverSeconds_ = 0, collectSeconds_ = 0;
  std::vector<Pair> pairs_;
};

/// `profile`'s platform for the binning device: the same link, and the clock
/// of the binning design itself on the profile's part where its report there
/// is valid (ecp5-5g: its LFE5UM5G-85F report; gen3x8: its LFE5U-85F report as
/// a stand-in, as for the stream device). Otherwise the profile's own clock
/// (the stream device's) stands in, its source saying why.
DeviceProfile binningProfile(const DeviceProfile& profile, const BinningParams& params,
                             const std::string& fpgaDir = "results/fpga");

/// One method per profile, named "accelerator binning on <profile>", on binningProfile(profile).
std::vector<MethodSpec> binningMethods(const BinningParams& params, const std::vector<DeviceProfile>& profiles);

}  // namespace bpaccel
