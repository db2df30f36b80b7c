#include "stream_words.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "bpaccel_shell.h"

namespace bpaccel::shell_words {

std::uint32_t commandHeader(std::uint32_t opcode) { return opcode | (BPACCEL_SHELL_PROTOCOL_VERSION << 8); }

void appendBoxes(const ShellFormat& format, std::span<const KeyBox> boxes, std::vector<std::uint32_t>& packet) {
  // Sized once and written through a pointer: a frame's thousands of boxes are most of its packet.
  const std::size_t at = packet.size();
  packet.resize(at + boxes.size() * format.boxWords);
  std::uint32_t* out = packet.data() + at;
  if (format.boxWords == 6) {
    for (const KeyBox& b : boxes) {
      out[0] = b.min[0], out[1] = b.min[1], out[2] = b.min[2], out[3] = b.max[0], out[4] = b.max[1], out[5] = b.max[2];
      out += 6;
    }
  } else {
    for (const KeyBox& b : boxes) {
      out[0] = b.min[0] | b.min[1] << 16, out[1] = b.min[2] | b.max[0] << 16, out[2] = b.max[1] | b.max[2] << 16;
      out += 3;
    }
  }
}

void checkKeys(const ShellFormat& format, std::span<const KeyBox> boxes, const std::string& where,
               std::size_t firstIndex) {
  if (format.keyWidth >= 32) return;
  std::uint32_t any = 0;  // the OR of every key: one branch for the whole span
  for (const KeyBox& b : boxes) any |= b.min[0] | b.min[1] | b.min[2] | b.max[0] | b.max[1] | b.max[2];
  if ((any >> format.keyWidth) == 0) return;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (int a = 0; a < 3; ++a)
      for (std::uint32_t key : {boxes[i].min[a], boxes[i].max[a]})
        if ((key >> format.keyWidth) != 0)
          throw std::invalid_argument(fmt::format("shell: {} box {} has key {:#x} on axis {}, wider than the "
                                                  "device's {} bits",
                                                  where, firstIndex + i, key, a, format.keyWidth));
}

void padToBeats(const ShellFormat& format, std::vector<std::uint32_t>& packet) {
  packet.resize(std::max<std::size_t>(format.paddedWords(packet.size()), format.wordsPerBeat), 0u);
}

}  // namespace bpaccel::shell_words
