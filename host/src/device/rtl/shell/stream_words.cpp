#include "stream_words.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "bpaccel_shell.h"

namespace bpaccel::shell_words {

std::uint32_t commandHeader(std::uint32_t opcode) { return opcode | (BPACCEL_SHELL_PROTOCOL_VERSION << 8); }

void appendBox(const ShellFormat& format, const KeyBox& box, std::vector<std::uint32_t>& packet) {
  if (format.boxWords == 6) {
    packet.insert(packet.end(), {box.min[0], box.min[1], box.min[2], box.max[0], box.max[1], box.max[2]});
  } else {
    packet.insert(packet.end(), {box.min[0] | box.min[1] << 16, box.min[2] | box.max[0] << 16,
                                 box.max[1] | box.max[2] << 16});
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
