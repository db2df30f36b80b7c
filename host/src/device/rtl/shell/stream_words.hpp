#pragma once
// The pieces every command and reply is made of (docs/protocol.md, "Words
// and beats"): the command header, boxes as words, the padding, the
// indices of a record. Shared by the CELLS and the FRAME codecs.

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "../../../core/types.hpp"
#include "shell_format.hpp"

namespace bpaccel::shell_words {

/// Word 0 of a command: the opcode in bits [7:0], the protocol version in [15:8].
std::uint32_t commandHeader(std::uint32_t opcode);

/// Appends the boxes: six keys a box, a word each, or two a word (the low
/// half first) where keys have 16 bits or fewer. The caller has checked the
/// keys (checkKeys).
void appendBoxes(const ShellFormat& format, std::span<const KeyBox> boxes, std::vector<std::uint32_t>& packet);

/// Whether no key of `boxes` has a bit set above the format's key width; else
/// throws std::invalid_argument naming `where`, the box (its index plus
/// `firstIndex`), the axis and the key.
void checkKeys(const ShellFormat& format, std::span<const KeyBox> boxes, const std::string& where,
               std::size_t firstIndex = 0);

/// Pads `packet` with zero words to whole beats (a packet has at least one beat).
void padToBeats(const ShellFormat& format, std::vector<std::uint32_t>& packet);

/// The indices (i, j) at the start of a record: {j, i} in one word, or i then j.
inline std::pair<std::uint32_t, std::uint32_t> recordIndices(const ShellFormat& format, const std::uint32_t* words) {
  if (format.indexWords == 1) return {words[0] & 0xFFFFu, words[0] >> 16};
  return {words[0], words[1]};
}

}  // namespace bpaccel::shell_words
