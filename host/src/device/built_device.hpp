#pragma once
// The device a program was built for: the generator's bpaccel_params.h (on the
// include path of every program that links a build's device, and installed
// beside this header) read into DeviceParams. The one place its macros become
// the host's parameters.

#include <string_view>

#include "bpaccel_params.h"
#include "device_params.hpp"

namespace bpaccel {

/// The parameters of the generated device whose header this program includes.
inline DeviceParams builtDeviceParams() {
  DeviceParams p;
  p.architecture = parseArchitecture(BPACCEL_ARCH);
  p.lanes = BPACCEL_M;
  p.capacity = BPACCEL_CAPACITY;
  p.runOverheadCycles = BPACCEL_RUN_OVERHEAD_CYCLES;
  p.readLatency = BPACCEL_READ_LATENCY;
  p.batchCells = BPACCEL_BATCH_CELLS;
  p.batchOverlapsLoads = BPACCEL_BATCH_OVERLAPS_LOADS != 0;
  p.bipartiteRuns = BPACCEL_BIPARTITE_RUNS != 0;
  p.keyWidth = BPACCEL_KEY_WIDTH;
  p.indexWidth = BPACCEL_INDEX_WIDTH;
  return p;
}

}  // namespace bpaccel
