#include "binning_params.hpp"

#include <bit>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

std::string_view frameErrorName(FrameError e) {
  static constexpr std::string_view names[] = {"NONE",         "COUNT_OVER_CAPACITY", "KEY_OUT_OF_GRID", "BOX_SPANS_CELLS",
                                               "GROUP_OVERFLOW", "LENGTH_MISMATCH",   "BAD_GRID",        "BOX_INVERTED",
                                               "KEY_TOO_WIDE", "BAD_COMMAND"};
  const auto k = static_cast<std::size_t>(e);
  return k < std::size(names) ? names[k] : "UNKNOWN";
}

void BinningParams::check() const {
  for (unsigned a : groupBits)
    if (a < 1 || a > cellBits) throw std::invalid_argument(fmt::format("binning: groupBits {} outside 1 .. cellBits", a));
  if (cellBits < 1 || cellBits > 8) throw std::invalid_argument(fmt::format("binning: cellBits {} outside 1 .. 8", cellBits));
  if (keyWidth < cellBits + 1 || keyWidth > 32)
    throw std::invalid_argument(fmt::format("binning: key width {} outside cellBits + 1 .. 32", keyWidth));
  if (lanesPerGroup < 1 || boxCapacity < 2 || groupCapacity < 1 || intakeBoxes < 1)
    throw std::invalid_argument("binning: lanes per group, box and group capacity, intake must be positive");
  if (pairsPerBeat < 1 || pairsPerBeat > groups())
    throw std::invalid_argument(fmt::format("binning: pairsPerBeat {} outside 1 .. groups", pairsPerBeat));
  if (laneQueueDepth < 1 || beatQueueDepth < 1 || cellQueueDepth < 1 || itemQueueDepth < 1 || hitQueueDepth < 2 ||
      mergeQueueDepth < 2)
    throw std::invalid_argument("binning: a queue depth below the generator's least");
}

std::size_t BinningParams::localCells() const {
  return std::size_t{1} << (3 * cellBits - groupBits[0] - groupBits[1] - groupBits[2]);
}

std::array<unsigned, 3> BinningParams::localDims(const std::array<unsigned, 3>& dims) const {
  std::array<unsigned, 3> l{};
  for (int a = 0; a < 3; ++a) l[a] = (dims[a] + (1u << groupBits[a]) - 1) >> groupBits[a];
  return l;
}

unsigned BinningParams::groupOf(const std::array<unsigned, 3>& cell) const {
  unsigned g = 0, shift = 0;
  for (int a = 0; a < 3; ++a) {
    g |= (cell[a] & ((1u << groupBits[a]) - 1)) << shift;
    shift += groupBits[a];
  }
  return g;
}

unsigned BinningParams::indexWidth() const {
  return std::max(1, static_cast<int>(std::bit_width(boxCapacity - 1)));
}

}  // namespace bpaccel
