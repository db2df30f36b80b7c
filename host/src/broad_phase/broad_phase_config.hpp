#pragma once
// How a BroadPhase is set up: partition, threads, batches, hand-overs, observer.

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>

#include "../partition/partition.hpp"

namespace bpaccel {

class BroadPhaseObserver;

/// How a worker hands its batches to the device:
/// - Synchronous: it waits for each answer and decodes it.
/// - Asynchronous (batches of at least 2 cells): three threads. The worker's
///   thread fills batches and hands each over to an AsyncBackend (the device
///   on a thread of its own) and goes on at once; a decoder thread
///   (SerialStage) waits for each answer and decodes it. At most
///   kBatchesInFlight batches are handed over and not yet decoded; the worker
///   waits for the oldest before it hands over one more.
/// - Polled: two threads, where a card would leave one. The device's thread
///   polls for the next hand-over (kDevicePollMicroseconds) as a card takes a
///   doorbell; the worker decodes the answers itself: after each hand-over
///   those that have arrived, and it polls for an answer it must have (for
///   room, and at the frame's end). No thread waits to be woken during a
///   frame (a wake-up cost 22-62 us on the virtual machines here), but each
///   polling thread takes a core.
/// The pairs (in the same order), the counters and the hand-overs are the same in all three.
enum class HandOvers { Synchronous, Asynchronous, Polled };

/// Hand-overs an asynchronous worker keeps handed over and not yet decoded:
/// with that many out, it waits for the oldest before it hands over the next.
inline constexpr std::size_t kBatchesInFlight = 3;

/// How long a polled device's thread polls for the next hand-over after each
/// one before it sleeps: longer than the gaps between a frame's hand-overs
/// here (up to about 0.1 ms), short enough that it sleeps between frames.
inline constexpr std::chrono::microseconds kDevicePollMicroseconds{250};

/// How many boxes a cell holds, about (each partition's own rule): a number,
/// none (the scene is one cell) or automatic (the default: the broad phase
/// chooses it, and the partition too unless one is named, frame by frame;
/// automatic_choice.hpp). Converts from a number, std::nullopt and
/// std::optional<std::size_t>, as the older optional field did.
class CellSize {
 public:
  constexpr CellSize() = default;
  constexpr CellSize(std::size_t boxes) : kind_(Kind::Boxes), boxes_(boxes) {}  // NOLINT: a number is a cell size
  constexpr CellSize(std::nullopt_t) : kind_(Kind::None) {}                    // NOLINT
  constexpr CellSize(const std::optional<std::size_t>& c)                      // NOLINT
      : kind_(c ? Kind::Boxes : Kind::None), boxes_(c.value_or(0)) {}
  static constexpr CellSize automatic() { return {}; }
  constexpr bool isAutomatic() const { return kind_ == Kind::Automatic; }
  /// The fixed choice: a number, or nullopt for none. Throws std::logic_error when automatic.
  std::optional<std::size_t> fixed() const;
  /// "auto", or cellSizeName of the fixed choice.
  std::string name() const;
  friend constexpr bool operator==(const CellSize&, const CellSize&) = default;

 private:
  enum class Kind { Automatic, None, Boxes };
  Kind kind_ = Kind::Automatic;
  std::size_t boxes_ = 0;
};

struct BroadPhaseConfig {
  /// Automatic by default; see CellSize.
  CellSize cellSize;
  /// Automatic (the default) with an automatic cell size: both chosen each
  /// frame; with a cell size of the caller's: the k-d tree, as a cell size
  /// given alone has always meant.
  PartitionKind partition = PartitionKind::Automatic;
  /// Workers, each with a device of its own (only with a backend factory).
  std::size_t threads = 1;
  /// Cells per hand-over to the device (Backend::runBatch); 1 hands each cell
  /// over on its own, straight from the partition's storage.
  std::size_t cellsPerBatch = 1;
  /// Slow start: a frame's first hand-over holds this many cells, each next
  /// one twice as many up to cellsPerBatch; 0: every hand-over holds cellsPerBatch.
  std::size_t firstBatchCells = 0;
  /// Only with a backend factory; the asynchronous kinds need cellsPerBatch of at least 2.
  HandOvers handOvers = HandOvers::Synchronous;
  /// Told each frame's timing; none: no clock is read. Not owned: it must outlive the broad phase.
  BroadPhaseObserver* observer = nullptr;

  /// The first hand-over's cells (firstBatchCells, at most cellsPerBatch).
  std::size_t firstBatch() const {
    return firstBatchCells && firstBatchCells < cellsPerBatch ? firstBatchCells : cellsPerBatch;
  }
  /// Throws std::invalid_argument naming the first setting no broad phase can run with.
  void check() const;
};

/// "none" (the scene is one cell) or a positive integer, as the command lines
/// spell a cell size; throws std::invalid_argument naming the text otherwise.
std::optional<std::size_t> parseCellSize(const std::string& text);
/// The same spelling of a cell size.
std::string cellSizeName(const std::optional<std::size_t>& cellSize);


}  // namespace bpaccel
