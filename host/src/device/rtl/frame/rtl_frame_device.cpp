#include "rtl_frame_device.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

// This translation unit sees the binning shell's emission first on its include path.
#include "../../binning/binning_params_of_header.hpp"
#include "../shell/shell_identity_of_header.hpp"
#include "../verilated_shell_transport_impl.hpp"
#include "VBinningShell.h"

static_assert(bpaccel::verilated_shell::kWords<VBinningShell> == BPACCEL_SHELL_WORDS_PER_BEAT &&
                  bpaccel::verilated_shell::kDualClock<VBinningShell> == (BPACCEL_SHELL_DUAL_CLOCK != 0),
              "the Verilated binning shell's ports and its bpaccel_shell.h are of different emissions");

template class bpaccel::VerilatedShellTransportOf<VBinningShell>;

namespace bpaccel {

ShellIdentity builtFrameShellIdentity() { return identityOfIncludedShellHeader(); }
BinningParams builtFrameShellParams() { return binningParamsOfIncludedHeader(); }

FrameError frameErrorOfShellCode(std::uint32_t code) {
  switch (code) {
    case BPACCEL_SHELL_ERR_NONE: return FrameError::None;
    case BPACCEL_SHELL_ERR_COUNT_OVER_CAPACITY: return FrameError::CountOverCapacity;
    case BPACCEL_SHELL_ERR_KEY_OUT_OF_GRID: return FrameError::KeyOutOfGrid;
    case BPACCEL_SHELL_ERR_BOX_SPANS_CELLS: return FrameError::BoxSpansCells;
    case BPACCEL_SHELL_ERR_GROUP_OVERFLOW: return FrameError::GroupOverflow;
    case BPACCEL_SHELL_ERR_LENGTH_MISMATCH: return FrameError::LengthMismatch;
    case BPACCEL_SHELL_ERR_BAD_GRID: return FrameError::BadGrid;
    case BPACCEL_SHELL_ERR_BOX_INVERTED: return FrameError::BoxInverted;
    case BPACCEL_SHELL_ERR_KEY_TOO_WIDE: return FrameError::KeyTooWide;
    case BPACCEL_SHELL_ERR_BAD_COMMAND: return FrameError::BadCommand;
    default: throw std::invalid_argument(fmt::format("a FRAME reply carries no error {} ({})", code, shellErrorName(code)));
  }
}

RtlFrameDevice::RtlFrameDevice(RtlFrameDeviceConfig config)
    : params_(builtFrameShellParams()),
      transport_(std::make_unique<VerilatedShellTransportOf<VBinningShell>>(std::move(config.shell))),
      driver_(std::make_unique<ShellDriver>(*transport_, builtFrameShellIdentity(), config.driver)) {
  params_.check();
}

RtlFrameDevice::~RtlFrameDevice() = default;

FrameReply RtlFrameDevice::runFrame(const FrameCommand& command) {
  if (command.count() != command.boxes.size())
    throw std::invalid_argument(fmt::format("{}: a header n of {} for {} boxes: the driver sends n = the boxes",
                                            name(), command.count(), command.boxes.size()));
  const std::size_t n = command.boxes.size();
  FrameReply reply;
  // The header's errors, which come before any box's: the driver does not send such a frame.
  const bool dimsFit = std::ranges::all_of(command.dims, [&](unsigned d) { return d >= 1 && d <= params_.maxDim(); });
  if (n > params_.boxCapacity || !dimsFit) {
    reply.error = n > params_.boxCapacity ? FrameError::CountOverCapacity : FrameError::BadGrid;
    return reply;
  }
  Trailer trailer;
  try {
    trailer = driver_->runFrame(command.boxes, {.shift = command.shift, .cells = command.dims}, n * (n - (n > 0)) / 2,
                                reply.pairs);
  } catch (const ShellDeviceError& e) {
    trailer = e.trailer();
    reply.error = frameErrorOfShellCode(e.code());
    reply.detail = e.detail();
  }
  reply.cycles = trailer.deviceCycles;
  reply.issueCycles = trailer.issueCycles;
  reply.stallCycles = trailer.stallCycles;
  reply.boxesReceived = trailer.boxes;
  if (reply.error == FrameError::None) reply.phases.intake = trailer.intakeCycles;
  return reply;
}

}  // namespace bpaccel
