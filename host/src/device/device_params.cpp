#include "device_params.hpp"

#include <bit>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace bpaccel {

std::string_view architectureName(Architecture architecture) {
  return architecture == Architecture::Seed ? "seed" : "stream";
}

Architecture parseArchitecture(std::string_view name) {
  if (name == "seed") return Architecture::Seed;
  if (name == "stream") return Architecture::Stream;
  throw std::invalid_argument(fmt::format("no architecture named '{}' (seed or stream)", name));
}

DeviceParams DeviceParams::seed(std::size_t lanes, std::size_t capacity, std::uint64_t runOverheadCycles) {
  DeviceParams p;
  p.architecture = Architecture::Seed;
  p.lanes = lanes;
  p.capacity = capacity;
  p.runOverheadCycles = runOverheadCycles;
  p.readLatency = 0;
  p.batchOverlapsLoads = false;
  p.bipartiteRuns = false;
  return p;
}

DeviceParams DeviceParams::stream(std::size_t lanes, std::size_t capacity, std::uint64_t runOverheadCycles,
                                  std::uint64_t readLatency, bool overlapsLoads) {
  DeviceParams p;
  p.architecture = Architecture::Stream;
  p.lanes = lanes;
  p.capacity = capacity;
  p.runOverheadCycles = runOverheadCycles;
  p.readLatency = readLatency;
  p.batchOverlapsLoads = overlapsLoads;
  p.bipartiteRuns = true;
  return p;
}

void DeviceParams::check() const {
  const auto arch = architectureName(architecture);
  if (keyWidth < 1 || keyWidth > 32)
    throw std::invalid_argument(fmt::format("{} device: key width {} outside 1 .. 32", arch, keyWidth));
  if (lanes == 0 || capacity < 2)
    throw std::invalid_argument(fmt::format("{} device: invalid m = {} / capacity = {}", arch, lanes, capacity));
  // Only the seed architecture stripes objects over m memories.
  if (architecture == Architecture::Seed && capacity % lanes != 0)
    throw std::invalid_argument(
        fmt::format("seed device: capacity {} is not a multiple of m = {} (its memories)", capacity, lanes));
  if (architecture == Architecture::Seed && bipartiteRuns)
    throw std::invalid_argument("seed device: the seed's hardware has no bipartite runs");
  if (batchCells == 0) throw std::invalid_argument(fmt::format("{} device: a batch must hold at least one cell", arch));
}

std::size_t DeviceParams::loadBoxBytes() const { return bpaccel::loadBoxBytes(keyWidth); }

std::size_t DeviceParams::resultBeatBytes() const {
  const std::size_t index = indexWidth ? indexWidth : std::bit_width(capacity - 1);
  return (2 * index + lanes + 7) / 8;
}

}  // namespace bpaccel
