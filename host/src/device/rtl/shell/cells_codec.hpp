#pragma once
// The CELLS command and its reply (docs/protocol.md): a batch of cells for
// the host-partitioned devices (seed, stream).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "../../../core/types.hpp"
#include "shell_format.hpp"
#include "shell_reply.hpp"

namespace bpaccel {

/// A batch of cells as a Backend hands it over: each cell's boxes, and one
/// split per cell (0: all pairs; na: only pairs i < na <= j) or none.
struct CellsCommand {
  std::span<const std::span<const KeyBox>> cells;
  std::span<const std::size_t> splits;

  std::size_t split(std::size_t k) const { return splits.empty() ? 0 : splits[k]; }
};

/// Replaces `packet` with the command's words, padded to whole beats. Throws
/// std::invalid_argument, naming the cell (and box), for what the device
/// would refuse: a cell above the capacity, a split it cannot run, a key
/// wider than its keys.
void encodeCells(const ShellFormat& format, const CellsCommand& command, std::vector<std::uint32_t>& packet);

/// Most words the reply to `command` can have: a record per issued cycle at
/// most, whole beats, and the trailer.
std::size_t cellsReplyWords(const ShellFormat& format, const CellsCommand& command);

/// Appends each cell's pairs (indices within the cell, i < j, in the order the
/// records came) to `out`, pushing out.size() onto `cellEnds` after each of
/// the command's cells. Throws ShellProtocolError, leaving `out` and
/// `cellEnds` as they were, for a reply that cannot answer `command`: a
/// record of an unknown or earlier cell, a mask bit above the lanes, a pair
/// the cell cannot have (not i < j < count, or not across its split), or
/// counts that disagree with the trailer's.
void decodeCellsReply(const ShellFormat& format, std::span<const std::uint32_t> reply, const Trailer& trailer,
                      const CellsCommand& command, std::vector<Pair>& out, std::vector<std::size_t>& cellEnds);

}  // namespace bpaccel
