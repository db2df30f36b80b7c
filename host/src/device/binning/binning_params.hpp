#pragma once
// The binning device's parameters (bpaccel.binning.BinningParams) as the host
// needs them, and the frame errors of the protocol's FRAME command.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace bpaccel {

/// Error codes of a FRAME reply (BinningErrorCode; the same numbers in the
/// generated header and the reply trailer).
enum class FrameError : std::uint8_t {
  None = 0,
  CountOverCapacity = 1,  // the header's n is above the box capacity
  KeyOutOfGrid = 2,       // a key's cell (key >> shift) is not below the grid's cells on its axis
  BoxSpansCells = 3,      // a box covers more than two cells on an axis
  GroupOverflow = 4,      // a lane group's entry memory is full
  LengthMismatch = 5,     // the packet ended before n boxes, or a box came after the n-th
  BadGrid = 6,            // shift above the largest, or a grid dimension 0 or above 2^cellBits
  BoxInverted = 7,        // a box's min key above its max key on an axis
  KeyTooWide = 8,         // (shell) a key's bits above the key width are not zero
  BadCommand = 9,         // (shell) an opcode or version the device does not answer
};
/// "GROUP_OVERFLOW", ... as the protocol names the codes.
std::string_view frameErrorName(FrameError e);

/// Every parameter of a binning device that its behaviour and timing depend on.
struct BinningParams {
  std::array<unsigned, 3> groupBits{2, 2, 1};  // (ax, ay, az): 2^a groups per axis
  unsigned lanesPerGroup = 2;                  // g
  unsigned keyWidth = 12;
  unsigned cellBits = 4;         // at most 2^cellBits cells per axis
  std::size_t boxCapacity = 8192;
  std::size_t groupCapacity = 1024;  // entries per group memory
  unsigned intakeBoxes = 4;          // w: boxes taken a cycle
  unsigned pairsPerBeat = 8;         // P: pairs sent a cycle, merge clusters
  unsigned memoryReadLatency = 3;    // entry and order memory: read to data
  unsigned laneQueueDepth = 2;
  unsigned beatQueueDepth = 4;
  unsigned cellQueueDepth = 4;
  unsigned itemQueueDepth = 8;
  unsigned hitQueueDepth = 8;
  unsigned mergeQueueDepth = 2;
  unsigned hitLatency = 2;  // schedule cycle to hits at the group's hit queue
  std::string fingerprint;  // BinningParams.fingerprint of the generator

  /// Throws std::invalid_argument naming the first value no generator builds.
  void check() const;
  unsigned groups() const { return 1u << (groupBits[0] + groupBits[1] + groupBits[2]); }
  unsigned lanes() const { return groups() * lanesPerGroup; }
  /// Bits of a key below its cell: the largest shift.
  unsigned maxShift() const { return keyWidth - cellBits; }
  unsigned maxDim() const { return 1u << cellBits; }
  /// Rows of each group's cell table.
  std::size_t localCells() const;
  /// A group's local cells per axis for a frame of `dims`: ceil(D / 2^a).
  std::array<unsigned, 3> localDims(const std::array<unsigned, 3>& dims) const;
  /// The group of a global cell: (cx mod 2^ax, cy mod 2^ay, cz mod 2^az), x lowest.
  unsigned groupOf(const std::array<unsigned, 3>& cell) const;
  /// Bits of a box index (the reply's record format: one word when <= 16).
  unsigned indexWidth() const;
};

/// The binning device the generator's bpaccel_binning_params.h describes (built_binning.hpp).
BinningParams builtBinningParams();

}  // namespace bpaccel
