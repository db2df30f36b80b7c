#pragma once
// The FRAME command and its reply (docs/protocol.md): a whole frame for the
// binning device, which bins the boxes itself and returns global pairs.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "../../../core/types.hpp"
#include "shell_format.hpp"
#include "shell_reply.hpp"

namespace bpaccel {

/// The frame's grid: a key's cell coordinate is key >> shift, and the grid
/// has cells[a] cells on axis a.
struct FrameGrid {
  unsigned shift = 0;
  std::array<unsigned, 3> cells{1, 1, 1};
};

/// Replaces `packet` with the FRAME command's words, padded to whole beats.
/// Throws std::invalid_argument for what no device takes: more boxes than
/// the capacity, a grid the header cannot hold or the device cannot bin
/// (cells an axis outside 1 .. min(255, 2^cellBits)), a key wider than the
/// device's (naming the box). Keys outside the grid and boxes spanning more
/// than two cells are the device's to report (KEY_OUT_OF_GRID, BOX_SPANS_CELLS).
void encodeFrame(const ShellFormat& format, std::span<const KeyBox> boxes, const FrameGrid& grid,
                 std::vector<std::uint32_t>& packet);

/// Words of a reply with at most `maxPairs` records, whole beats, and the trailer.
std::size_t frameReplyWords(const ShellFormat& format, std::size_t maxPairs);

/// Appends the frame's pairs (global indices, i < j < boxes) to `out`.
/// Throws ShellProtocolError, leaving `out` as it was, for a pair outside
/// the frame or a record count that is not the trailer's pair count. (Each
/// pair comes once by the protocol; this does not look for duplicates.)
void decodeFrameReply(const ShellFormat& format, std::span<const std::uint32_t> reply, const Trailer& trailer,
                      std::size_t boxes, std::vector<Pair>& out);

}  // namespace bpaccel
