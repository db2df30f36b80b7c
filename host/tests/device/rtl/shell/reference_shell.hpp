#pragma once
// A plain reference of the shell's protocol for the driver's tests, written
// from docs/protocol.md and independent of the driver's codecs: it parses a
// command's words, finds every pair by brute force on the keys, and packs
// the reply (records, zero words to the beat, the trailer).

#include <cstdint>
#include <set>
#include <vector>

#include "bpaccel_shell.h"
#include "core/types.hpp"
#include "device/rtl/shell/shell_format.hpp"

namespace bpaccel::testing {

/// One record of a CELLS reply: the pairs (iBase + k, jBase + k) of the set bits k of `mask`.
struct CellsRecord {
  std::uint32_t cell, iBase, jBase;
  std::vector<std::uint32_t> mask;  // maskWords words
};

/// The trailer's words: HEADER, DETAIL, RECORDS, BOXES, DEVICE_CYCLES, ... as docs/protocol.md lists them.
struct ReferenceTrailer {
  std::uint32_t opcode = BPACCEL_SHELL_OP_CELLS, error = 0, detail = 0, records = 0, boxes = 0, cells = 0;
  std::uint64_t deviceCycles = 0, stallCycles = 0, issueCycles = 0, pairs = 0, intakeCycles = 0;
};

inline std::vector<std::uint32_t> trailerWords(const ReferenceTrailer& t) {
  return {0xB7u << 24 | t.opcode << 16 | t.error << 8,
          t.detail,
          t.records,
          t.boxes,
          static_cast<std::uint32_t>(t.deviceCycles),
          static_cast<std::uint32_t>(t.deviceCycles >> 32),
          static_cast<std::uint32_t>(t.stallCycles),
          static_cast<std::uint32_t>(t.stallCycles >> 32),
          static_cast<std::uint32_t>(t.issueCycles),
          static_cast<std::uint32_t>(t.issueCycles >> 32),
          static_cast<std::uint32_t>(t.pairs),
          static_cast<std::uint32_t>(t.pairs >> 32),
          static_cast<std::uint32_t>(t.intakeCycles),
          static_cast<std::uint32_t>(t.intakeCycles >> 32),
          t.cells,
          0u};
}

/// Records packed word by word, zeros to a whole beat, then the trailer.
inline std::vector<std::uint32_t> packReply(const ShellFormat& f, const std::vector<std::vector<std::uint32_t>>& records,
                                            const ReferenceTrailer& t) {
  std::vector<std::uint32_t> words;
  for (const auto& r : records) words.insert(words.end(), r.begin(), r.end());
  while (words.size() % f.wordsPerBeat != 0) words.push_back(0);
  const auto trailer = trailerWords(t);
  words.insert(words.end(), trailer.begin(), trailer.end());
  return words;
}

inline std::vector<std::uint32_t> indexWords(const ShellFormat& f, std::uint32_t i, std::uint32_t j) {
  if (f.indexWords == 1) return {(j << 16) | (i & 0xFFFFu)};
  return {i, j};
}

inline std::vector<std::uint32_t> cellsRecordWords(const ShellFormat& f, const CellsRecord& r) {
  auto words = indexWords(f, r.iBase, r.jBase);
  words.push_back(r.cell);
  words.insert(words.end(), r.mask.begin(), r.mask.end());
  return words;
}

/// The keys of box `b` of a packet whose boxes start at word `at`.
inline KeyBox boxAt(const ShellFormat& f, const std::vector<std::uint32_t>& words, std::size_t at) {
  std::uint32_t k[6];
  for (int q = 0; q < 6; ++q)
    k[q] = f.boxWords == 6 ? words[at + q] : (words[at + q / 2] >> (16 * (q % 2))) & 0xFFFFu;
  return {{k[0], k[1], k[2]}, {k[3], k[4], k[5]}};
}

/// Packs a cell's pairs into records greedily: a record's base is the first
/// pair not yet sent, and its mask takes every pair on the same diagonal
/// within m lanes of it.
inline std::vector<CellsRecord> recordsOf(const ShellFormat& f, std::uint32_t cell, const std::set<Pair>& pairs) {
  std::vector<CellsRecord> out;
  std::set<Pair> left = pairs;
  while (!left.empty()) {
    const Pair base = *left.begin();
    CellsRecord r{cell, base.first, base.second, std::vector<std::uint32_t>(f.maskWords(), 0u)};
    for (std::uint32_t k = 0; k < f.lanes; ++k)
      if (left.erase({base.first + k, base.second + k}) != 0) r.mask[k / 32] |= 1u << (k % 32);
    out.push_back(r);
  }
  return out;
}

/// The reply a correct CELLS device gives to `packet` (no error checks but
/// the opcode's): pairs by brute force, records by recordsOf, and counters
/// that follow from the work (not cycle-exact: the driver only passes them on).
inline std::vector<std::uint32_t> referenceCellsReply(const ShellFormat& f, const std::vector<std::uint32_t>& packet) {
  ReferenceTrailer t;
  t.opcode = packet[0] & 0xFFu;
  if (t.opcode != BPACCEL_SHELL_OP_CELLS || (packet[0] >> 8) != BPACCEL_SHELL_PROTOCOL_VERSION) {
    t.error = BPACCEL_SHELL_ERR_BAD_COMMAND;
    return packReply(f, {}, t);
  }
  std::vector<std::vector<std::uint32_t>> records;
  std::size_t at = 2;
  for (std::uint32_t c = 0; c < packet[1]; ++c) {
    const std::uint32_t count = packet[at], split = packet[at + 1];
    at += 2;
    std::vector<KeyBox> boxes;
    for (std::uint32_t b = 0; b < count; ++b, at += f.boxWords) boxes.push_back(boxAt(f, packet, at));
    std::set<Pair> pairs;
    for (std::uint32_t i = 0; i < count; ++i)
      for (std::uint32_t j = i + 1; j < count; ++j)
        if (overlaps(boxes[i], boxes[j]) && (split == 0 || (i < split && j >= split))) pairs.insert({i, j});
    for (const auto& r : recordsOf(f, c, pairs)) records.push_back(cellsRecordWords(f, r));
    t.pairs += pairs.size();
    t.boxes += count;
  }
  t.cells = packet[1];
  t.records = static_cast<std::uint32_t>(records.size());
  t.intakeCycles = t.boxes + 2;
  t.deviceCycles = t.intakeCycles + 10 * t.cells + t.pairs;
  t.issueCycles = t.pairs;
  return packReply(f, records, t);
}

}  // namespace bpaccel::testing
