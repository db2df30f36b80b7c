#include "frame_codec.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "bpaccel_shell.h"
#include "stream_words.hpp"

namespace bpaccel {

void encodeFrame(const ShellFormat& format, std::span<const KeyBox> boxes, const FrameGrid& grid,
                 std::vector<std::uint32_t>& packet) {
  if (boxes.size() > format.capacity)
    throw std::invalid_argument(
        fmt::format("shell: a frame of {} boxes, above the device's capacity {}", boxes.size(), format.capacity));
  if (format.cellBits == 0) throw std::invalid_argument("shell: the device bins no frames (CELL_BITS is 0)");
  const unsigned most = std::min(255u, 1u << std::min(format.cellBits, 8u));  // an 8-bit field each
  for (unsigned a = 0; a < 3; ++a)
    if (grid.cells[a] < 1 || grid.cells[a] > most)
      throw std::invalid_argument(fmt::format("shell: a grid of {} cells on axis {}, outside 1 .. {}", grid.cells[a],
                                              a, most));
  if (grid.shift >= 32) throw std::invalid_argument(fmt::format("shell: a grid shift of {} bits", grid.shift));
  shell_words::checkKeys(format, boxes, "frame");
  packet.clear();
  packet.reserve(format.paddedWords(4 + boxes.size() * format.boxWords));
  packet.push_back(shell_words::commandHeader(BPACCEL_SHELL_OP_FRAME));
  packet.push_back(static_cast<std::uint32_t>(boxes.size()));
  packet.push_back(grid.shift);
  packet.push_back(grid.cells[0] | grid.cells[1] << 8 | grid.cells[2] << 16);
  shell_words::appendBoxes(format, boxes, packet);
  shell_words::padToBeats(format, packet);
}

std::size_t frameReplyWords(const ShellFormat& format, std::size_t maxPairs) {
  return format.paddedWords(maxPairs * format.indexWords) + BPACCEL_SHELL_TRAILER_WORDS;
}

void decodeFrameReply(const ShellFormat& format, std::span<const std::uint32_t> reply, const Trailer& trailer,
                      std::size_t boxes, std::vector<Pair>& out) {
  const auto words = recordWordsOf(format, reply, trailer, format.indexWords);
  if (trailer.pairs != trailer.records)
    throw ShellProtocolError(fmt::format("shell: a FRAME reply of {} records counts {} pairs", trailer.records,
                                         trailer.pairs));
  const std::size_t before = out.size();
  out.reserve(before + trailer.records);
  for (std::size_t r = 0; r < trailer.records; ++r) {
    const auto [i, j] = shell_words::recordIndices(format, words.data() + r * format.indexWords);
    if (i >= j || j >= boxes) {
      out.resize(before);
      throw ShellProtocolError(
          fmt::format("shell: record {} reports the pair ({}, {}) of a frame of {} boxes", r, i, j, boxes));
    }
    out.emplace_back(i, j);
  }
}

}  // namespace bpaccel
