#include "answer_decoder.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

void AnswerDecoder::decodeBatch(const Batch& batch, std::span<const Pair> pairs, std::span<const std::size_t> ends,
                                const std::string& device) {
  if (ends.size() != batch.cells.size() || (!ends.empty() && ends.back() != pairs.size()))
    throw std::logic_error(fmt::format("broad phase: backend {} returned {} cell ends for a batch of {} cells", device,
                                       ends.size(), batch.cells.size()));
  Pair* to = roomFor(pairs.size());
  // In the partition's order, not the device's: the cells' items and bits
  // are then read in the order they lie in memory.
  for (std::size_t k = 0; k < batch.cells.size(); ++k) {
    const std::size_t c = batch.position[k], from = c == 0 ? 0 : ends[c - 1];
    to = keepPairs(pairs.subspan(from, ends[c] - from), batch.filter(k), narrowed_, to);
  }
  keptUntil(to);
}

void AnswerDecoder::decodeCell(const PairFilter& cell, std::span<const Pair> pairs) {
  keptUntil(keepPairs(pairs, cell, narrowed_, roomFor(pairs.size())));
}

}  // namespace bpaccel
