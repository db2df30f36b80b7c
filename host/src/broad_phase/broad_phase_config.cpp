#include "broad_phase_config.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

std::optional<std::size_t> CellSize::fixed() const {
  if (kind_ == Kind::Automatic) throw std::logic_error("cell size: automatic, not fixed");
  return kind_ == Kind::None ? std::nullopt : std::optional<std::size_t>(boxes_);
}

void BroadPhaseConfig::check() const {
  if (!cellSize.isAutomatic() && cellSize.fixed() && *cellSize.fixed() < 1)
    throw std::invalid_argument("broad phase: cell size must be at least 1");
  if (threads < 1) throw std::invalid_argument("broad phase: at least one thread");
  if (cellsPerBatch < 1) throw std::invalid_argument("broad phase: cells per batch must be at least 1");
  if (handOvers != HandOvers::Synchronous && cellsPerBatch < 2)
    throw std::invalid_argument("broad phase: asynchronous hand-overs need at least two cells per batch");
}

std::optional<std::size_t> parseCellSize(const std::string& text) {
  if (text == "none") return std::nullopt;
  std::size_t pos = 0;
  unsigned long long v = 0;
  try {
    v = std::stoull(text, &pos);
  } catch (const std::exception&) {
    pos = 0;
  }
  if (pos != text.size() || v < 1 || text.front() == '-')
    throw std::invalid_argument(fmt::format("'{}' is neither a positive integer nor 'none'", text));
  return static_cast<std::size_t>(v);
}

std::string cellSizeName(const std::optional<std::size_t>& cellSize) {
  return cellSize ? std::to_string(*cellSize) : "none";
}

std::string CellSize::name() const { return isAutomatic() ? "auto" : cellSizeName(fixed()); }

}  // namespace bpaccel
