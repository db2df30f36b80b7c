#include "cells_codec.hpp"

#include <bit>
#include <stdexcept>

#include <fmt/format.h>

#include "../../backend.hpp"
#include "bpaccel_shell.h"
#include "stream_words.hpp"

namespace bpaccel {
namespace {

void checkCell(const ShellFormat& format, std::span<const KeyBox> cell, std::size_t split, std::size_t k) {
  if (cell.size() > format.capacity)
    throw std::invalid_argument(
        fmt::format("shell: cell {} has {} boxes, above the device's capacity {}", k, cell.size(), format.capacity));
  if (split != 0 && !format.bipartite)
    throw std::invalid_argument(fmt::format("shell: cell {} has split {}, but the device has no bipartite runs", k,
                                            split));
  if (split != 0 && split >= cell.size())
    throw std::invalid_argument(
        fmt::format("shell: cell {} has split {}, not below its {} boxes", k, split, cell.size()));
  shell_words::checkKeys(format, cell, fmt::format("cell {}", k));
}

// Throws for a record the command's reply cannot hold.
void checkRecord(std::uint32_t cell, std::uint32_t lastCell, std::size_t cellCount, std::size_t r) {
  if (cell >= cellCount || cell < lastCell)
    throw ShellProtocolError(fmt::format("shell: record {} names cell {} after cell {} of a command of {} cells", r,
                                         cell, lastCell, cellCount));
}

// Throws for a pair cell k cannot have.
void checkPair(const CellsCommand& command, std::uint32_t k, std::uint32_t i, std::uint32_t j, std::size_t r) {
  const std::size_t split = command.split(k);
  if (i >= j || j >= command.cells[k].size() || (split != 0 && (i >= split || j < split)))
    throw ShellProtocolError(fmt::format("shell: record {} reports the pair ({}, {}) of cell {}, which has {} boxes "
                                         "and split {}",
                                         r, i, j, k, command.cells[k].size(), split));
}

// Throws when the trailer's counts disagree with the command and its decoded pairs.
void checkCounts(const Trailer& trailer, const CellsCommand& command, std::size_t pairs) {
  std::size_t boxes = 0;
  for (const auto& cell : command.cells) boxes += cell.size();
  if (trailer.pairs != pairs || trailer.cells != command.cells.size() || trailer.boxes != boxes)
    throw ShellProtocolError(fmt::format("shell: the trailer counts {} pairs, {} cells and {} boxes; the command had "
                                         "{} cells and {} boxes and its records hold {} pairs",
                                         trailer.pairs, trailer.cells, trailer.boxes, command.cells.size(), boxes,
                                         pairs));
}

}  // namespace

void encodeCells(const ShellFormat& format, const CellsCommand& command, std::vector<std::uint32_t>& packet) {
  const auto& cells = command.cells;
  if (!command.splits.empty() && command.splits.size() != cells.size())
    throw std::invalid_argument(
        fmt::format("shell: {} splits for {} cells (give one per cell, or none)", command.splits.size(), cells.size()));
  std::size_t boxes = 0;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    checkCell(format, cells[k], command.split(k), k);
    boxes += cells[k].size();
  }
  packet.clear();
  packet.reserve(format.paddedWords(2 + 2 * cells.size() + boxes * format.boxWords));
  packet.push_back(shell_words::commandHeader(BPACCEL_SHELL_OP_CELLS));
  packet.push_back(static_cast<std::uint32_t>(cells.size()));
  for (std::size_t k = 0; k < cells.size(); ++k) {
    packet.push_back(static_cast<std::uint32_t>(cells[k].size()));
    packet.push_back(static_cast<std::uint32_t>(command.split(k)));
    shell_words::appendBoxes(format, cells[k], packet);
  }
  shell_words::padToBeats(format, packet);
}

std::size_t cellsReplyWords(const ShellFormat& format, const CellsCommand& command) {
  std::uint64_t records = 0;
  for (std::size_t k = 0; k < command.cells.size(); ++k)
    records += scheduleIssueCycles(command.cells[k].size(), format.lanes, command.split(k));
  return format.paddedWords(records * format.recordWords()) + BPACCEL_SHELL_TRAILER_WORDS;
}

void decodeCellsReply(const ShellFormat& format, std::span<const std::uint32_t> reply, const Trailer& trailer,
                      const CellsCommand& command, std::vector<Pair>& out, std::vector<std::size_t>& cellEnds) {
  const unsigned recordWords = format.recordWords();
  const auto words = recordWordsOf(format, reply, trailer, recordWords);
  const std::uint32_t indexMask = format.indexWidth >= 32 ? ~0u : (1u << format.indexWidth) - 1;
  const std::uint32_t highLanes = format.lanes % 32 == 0 ? 0u : ~0u << (format.lanes % 32);  // of the last mask word
  const std::size_t cellCount = command.cells.size();
  const std::size_t pairsBefore = out.size(), endsBefore = cellEnds.size();
  std::uint32_t cell = 0;
  try {
    for (std::size_t r = 0; r < trailer.records; ++r) {
      const std::uint32_t* record = words.data() + r * recordWords;
      const auto [iBase, jBase] = shell_words::recordIndices(format, record);
      const std::uint32_t recordCell = record[format.indexWords];
      checkRecord(recordCell, cell, cellCount, r);
      for (; cell < recordCell; ++cell) cellEnds.push_back(out.size());
      const std::uint32_t* masks = record + format.indexWords + 1;
      if ((masks[format.maskWords() - 1] & highLanes) != 0)
        throw ShellProtocolError(fmt::format("shell: record {} has a mask bit above lane {}", r, format.lanes - 1));
      for (unsigned w = 0; w < format.maskWords(); ++w)
        for (std::uint32_t mask = masks[w]; mask != 0; mask &= mask - 1) {
          const std::uint32_t lane = 32 * w + static_cast<std::uint32_t>(std::countr_zero(mask));
          const std::uint32_t i = (iBase + lane) & indexMask, j = (jBase + lane) & indexMask;
          checkPair(command, cell, i, j, r);
          out.emplace_back(i, j);
        }
    }
    for (; cell < cellCount; ++cell) cellEnds.push_back(out.size());
    checkCounts(trailer, command, out.size() - pairsBefore);
  } catch (...) {
    out.resize(pairsBefore);
    cellEnds.resize(endsBefore);
    throw;
  }
}

}  // namespace bpaccel
