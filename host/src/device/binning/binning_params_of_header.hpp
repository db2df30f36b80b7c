#pragma once
// The parameters of the binning device whose bpaccel_binning_params.h the
// including file sees (EmitBinning writes it). A program may hold several
// devices' parameters, one translation unit each with that device's
// emission first on its include path: hence a function of internal linkage.

#include "bpaccel_binning_params.h"
#include "binning_params.hpp"

namespace bpaccel {
namespace {

BinningParams binningParamsOfIncludedHeader() {
  BinningParams p;
  p.groupBits = {BPACCEL_BIN_GROUP_BITS_X, BPACCEL_BIN_GROUP_BITS_Y, BPACCEL_BIN_GROUP_BITS_Z};
  p.lanesPerGroup = BPACCEL_BIN_LANES_PER_GROUP;
  p.keyWidth = BPACCEL_BIN_KEY_WIDTH;
  p.cellBits = BPACCEL_BIN_CELL_BITS;
  p.boxCapacity = BPACCEL_BIN_BOX_CAPACITY;
  p.groupCapacity = BPACCEL_BIN_GROUP_CAPACITY;
  p.intakeBoxes = BPACCEL_BIN_INTAKE_BOXES;
  p.pairsPerBeat = BPACCEL_BIN_PAIRS_PER_BEAT;
  p.memoryReadLatency = BPACCEL_BIN_MEMORY_READ_LATENCY;
  p.laneQueueDepth = BPACCEL_BIN_LANE_QUEUE_DEPTH;
  p.beatQueueDepth = BPACCEL_BIN_BEAT_QUEUE_DEPTH;
  p.cellQueueDepth = BPACCEL_BIN_CELL_QUEUE_DEPTH;
  p.itemQueueDepth = BPACCEL_BIN_ITEM_QUEUE_DEPTH;
  p.hitQueueDepth = BPACCEL_BIN_HIT_QUEUE_DEPTH;
  p.mergeQueueDepth = BPACCEL_BIN_MERGE_QUEUE_DEPTH;
  p.hitLatency = BPACCEL_BIN_HIT_LATENCY;
  p.fingerprint = BPACCEL_BIN_FINGERPRINT;
  return p;
}

}  // namespace
}  // namespace bpaccel
