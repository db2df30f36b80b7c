#pragma once
// The FRAME command of the binning device (docs/protocol.md): n boxes of keys
// with the frame's grid in, every overlapping pair once as global indices
// out, with the reply's error and counters. One interface for the C++ model
// and, later, the Verilated core behind the shell.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "../../core/types.hpp"
#include "binning_params.hpp"

namespace bpaccel {

/// One FRAME command: the header (n, shift, dims) and the boxes in stream order.
struct FrameCommand {
  std::span<const KeyBox> boxes;
  unsigned shift = 0;                // a key's cell coordinate is key >> shift
  std::array<unsigned, 3> dims{1, 1, 1};  // cells per axis
  std::optional<std::size_t> n;      // the header's n; none: boxes.size()
  std::size_t count() const { return n.value_or(boxes.size()); }
};

/// Where the device's cycles went, from its slowest group (docs/binning.md, "Phases").
struct FramePhases {
  std::uint64_t intake = 0;   // cycles 0 .. T: header and intake
  std::uint64_t prefix = 0;   // Lc: the prefix pass
  std::uint64_t sort = 0;     // the slowest group's sort
  std::uint64_t compute = 0;  // the slowest group's compute
  std::uint64_t drain = 0;    // after the last group: the output path and the summary
};

/// The reply: pairs (i < j) in the order the device sends them, then the trailer's figures.
struct FrameReply {
  FrameError error = FrameError::None;
  std::uint64_t detail = 0;  // the first offending box (or boxes received, for a short packet)
  std::vector<Pair> pairs;
  std::uint64_t cycles = 0;  // from the header's cycle to the summary
  std::uint64_t issueCycles = 0;
  std::uint64_t stallCycles = 0;
  std::uint64_t boxesReceived = 0;
  std::uint64_t entries = 0;       // entries binned, over all groups
  std::uint64_t fullestGroup = 0;  // entries of the fullest group
  FramePhases phases;              // only for a frame without error
};

/// A device that answers FRAME commands.
class FrameDevice {
 public:
  virtual ~FrameDevice() = default;
  virtual std::string name() const = 0;
  virtual const BinningParams& params() const = 0;
  /// Runs one frame; a frame the device refuses comes back with its error, never as an exception.
  virtual FrameReply runFrame(const FrameCommand& command) = 0;
};

}  // namespace bpaccel
