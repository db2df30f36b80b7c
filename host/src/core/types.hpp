#pragma once
// Basic value types shared by every part of the host.

#include <array>
#include <cstdint>
#include <utility>

namespace bpaccel {

/// An axis-aligned bounding box in float coordinates, as a physics engine has it.
struct Aabb {
  std::array<float, 3> min;
  std::array<float, 3> max;
};

/// The same box as order-preserving unsigned keys, as the hardware compares it.
struct KeyBox {
  std::array<std::uint32_t, 3> min;
  std::array<std::uint32_t, 3> max;
};

/// A scene's bounds in keys: the lowest min and the highest max per axis
/// (for no boxes, lo above hi).
struct KeyBounds {
  std::array<std::uint32_t, 3> lo{~0u, ~0u, ~0u};
  std::array<std::uint32_t, 3> hi{0, 0, 0};
};

/// Inclusive overlap on every axis: boxes that touch overlap (Bullet's rule).
inline bool overlaps(const KeyBox& a, const KeyBox& b) {
  return a.min[0] <= b.max[0] && b.min[0] <= a.max[0] &&  //
         a.min[1] <= b.max[1] && b.min[1] <= a.max[1] &&  //
         a.min[2] <= b.max[2] && b.min[2] <= a.max[2];
}

/// The same on floats, as the host rechecks pairs: a NaN coordinate keeps boxes apart.
inline bool overlaps(const Aabb& a, const Aabb& b) {
  return a.min[0] <= b.max[0] && b.min[0] <= a.max[0] &&  //
         a.min[1] <= b.max[1] && b.min[1] <= a.max[1] &&  //
         a.min[2] <= b.max[2] && b.min[2] <= a.max[2];
}

/// The same without a branch: for loops over pairs whose outcome is hard to predict.
inline bool overlapsBranchFree(const KeyBox& a, const KeyBox& b) {
  return static_cast<bool>((static_cast<unsigned>(a.min[0] <= b.max[0]) & static_cast<unsigned>(b.min[0] <= a.max[0])) &
                           (static_cast<unsigned>(a.min[1] <= b.max[1]) & static_cast<unsigned>(b.min[1] <= a.max[1])) &
                           (static_cast<unsigned>(a.min[2] <= b.max[2]) & static_cast<unsigned>(b.min[2] <= a.max[2])));
}

/// An overlapping pair of object indices, first < second.
using Pair = std::pair<std::uint32_t, std::uint32_t>;

/// What the backends spent on one frame (or one call), summed over all runs.
struct RunStats {
  std::uint64_t runs = 0;          // accelerator runs (one per cell or chunk pair)
  std::uint64_t batches = 0;       // hand-overs to the device: one per run, one per hardware batch of cells
  std::uint64_t loadCycles = 0;    // hardware cycles spent loading boxes before each start, summed
  std::uint64_t cycles = 0;        // hardware cycles, start to done, summed
  std::uint64_t issueCycles = 0;   // cycles the comparator array had work
  std::uint64_t stallCycles = 0;   // cycles lost to the consumer
  std::uint64_t hits = 0;          // pairs the hardware reported (before the cell filter)
  std::uint64_t boxesSent = 0;     // boxes loaded into the accelerator
  std::uint64_t beatsReceived = 0; // result beats read back

  /// Every cycle the device is busy: loading, computing and draining.
  std::uint64_t deviceCycles() const { return loadCycles + cycles; }

  RunStats& operator+=(const RunStats& o) {
    runs += o.runs;
    batches += o.batches;
    loadCycles += o.loadCycles;
    cycles += o.cycles;
    issueCycles += o.issueCycles;
    stallCycles += o.stallCycles;
    hits += o.hits;
    boxesSent += o.boxesSent;
    beatsReceived += o.beatsReceived;
    return *this;
  }
};

}  // namespace bpaccel
