#pragma once
// What one generated device is: the generator's parameters (bpaccel_params.h)
// that the host's model of it needs, in one struct.

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace bpaccel {

/// The hardware architectures the generator builds (BPACCEL_ARCH).
enum class Architecture {
  Seed,    // the published design: objects striped over m memories
  Stream,  // one memory read a cycle into a window of m lanes; bipartite runs
};
/// "seed" or "stream", as BPACCEL_ARCH spells it.
std::string_view architectureName(Architecture architecture);
/// The inverse; throws std::invalid_argument naming the text for another.
Architecture parseArchitecture(std::string_view name);

/// Bytes of one box on a device's load port: six keys of `keyWidth` bits (the link model's box).
constexpr std::size_t loadBoxBytes(unsigned keyWidth) { return (6 * std::size_t{keyWidth} + 7) / 8; }

/// A device's parameters, as the generator's header names them.
struct DeviceParams {
  Architecture architecture = Architecture::Stream;  // BPACCEL_ARCH
  std::size_t lanes = 8;                             // BPACCEL_M: pair tests a cycle
  std::size_t capacity = 2048;                       // BPACCEL_CAPACITY: most boxes a run holds
  std::uint64_t runOverheadCycles = 5;               // BPACCEL_RUN_OVERHEAD_CYCLES
  /// BPACCEL_READ_LATENCY: cycles before a stream run's first issue; the
  /// seed's runs issue at once, whatever this says.
  std::uint64_t readLatency = 4;
  std::size_t batchCells = 64;                       // BPACCEL_BATCH_CELLS: cells a hardware batch holds
  bool batchOverlapsLoads = true;                    // BPACCEL_BATCH_OVERLAPS_LOADS
  bool bipartiteRuns = true;                         // BPACCEL_BIPARTITE_RUNS (the stream's only)
  unsigned keyWidth = 32;                            // BPACCEL_KEY_WIDTH, 1 .. 32
  unsigned indexWidth = 0;                           // BPACCEL_INDEX_WIDTH; 0: enough bits for capacity

  /// A seed device: no bipartite runs, no overlapped loads.
  static DeviceParams seed(std::size_t lanes, std::size_t capacity, std::uint64_t runOverheadCycles);
  /// A stream device with bipartite runs; loads overlap runs where `overlapsLoads`.
  static DeviceParams stream(std::size_t lanes, std::size_t capacity, std::uint64_t runOverheadCycles,
                             std::uint64_t readLatency, bool overlapsLoads = false);

  /// Throws std::invalid_argument naming the first parameter the generator could not have built.
  void check() const;
  /// Cycles before a run's first issue: the read latency on the stream, none on the seed.
  std::uint64_t startupCycles() const { return architecture == Architecture::Stream ? readLatency : 0; }
  /// Bytes of one box on the load port: six keys of keyWidth bits.
  std::size_t loadBoxBytes() const;
  /// Bytes of one result beat ({iBase, jBase, mask[m]}).
  std::size_t resultBeatBytes() const;
};

}  // namespace bpaccel
