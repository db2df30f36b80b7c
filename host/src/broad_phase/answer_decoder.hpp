#pragma once
// One worker's share of a frame's pairs: each device answer decoded (cell
// indices to scene indices, each pair kept once) and its counters added.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "../core/types.hpp"
#include "batch.hpp"
#include "pair_filter.hpp"

namespace bpaccel {

class AnswerDecoder {
 public:
  /// `deviceKeyWidth` below 32: the device compared narrowed keys, so each
  /// pair is checked with the full ones too.
  void setDeviceKeyWidth(unsigned width) { narrowed_ = width < 32; }
  void startFrame() {
    pairs_.clear();
    stats_ = {};
  }
  /// A batch's answer: the device's pairs (local to each cell, the device's
  /// order of cells) and its cell ends. Throws std::logic_error, naming
  /// `device`, when the ends do not fit the batch.
  void decodeBatch(const Batch& batch, std::span<const Pair> pairs, std::span<const std::size_t> cellEnds,
                   const std::string& device);
  /// One cell's answer.
  void decodeCell(const PairFilter& cell, std::span<const Pair> pairs);
  void addStats(const RunStats& stats) { stats_ += stats; }
  std::vector<Pair>& pairs() { return pairs_; }
  const RunStats& stats() const { return stats_; }

 private:
  // Room in pairs_ for `hits` more pairs; decoding writes into it, branch-free,
  // and then cuts what it did not use (keptUntil).
  Pair* roomFor(std::size_t hits) {
    const std::size_t at = pairs_.size();
    pairs_.resize(at + hits);
    return pairs_.data() + at;
  }
  void keptUntil(const Pair* end) { pairs_.resize(static_cast<std::size_t>(end - pairs_.data())); }

  bool narrowed_ = false;
  std::vector<Pair> pairs_;
  RunStats stats_;
};

}  // namespace bpaccel
