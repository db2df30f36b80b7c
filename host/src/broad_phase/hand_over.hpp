#pragma once
// How a worker's cells reach the device and its answers come back: one
// interface, one class per kind of hand-over (HandOvers).

#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "../device/backend.hpp"
#include "answer_decoder.hpp"
#include "batch.hpp"
#include "broad_phase_config.hpp"
#include "timing.hpp"

namespace bpaccel {

/// What the broad phase needs to know of the device behind a hand-over.
struct BackendTraits {
  std::string name;
  std::size_t capacity = 0;
  bool bipartite = false;
  unsigned keyWidth = 32;
};

/// Hands cells over to one device and decodes its answers into `decoder`,
/// timing each hand-over with `timer` (both the worker's, which outlive it).
class HandOver {
 public:
  virtual ~HandOver() = default;
  HandOver(const HandOver&) = delete;
  HandOver& operator=(const HandOver&) = delete;

  const BackendTraits& backend() const { return traits_; }
  /// Before each frame: what a failed frame left with the device settled.
  virtual void startFrame() {}
  /// One cell on its own (cellsPerBatch 1, synchronous hand-overs only):
  /// `toDevice` its boxes as the device gets them, `deviceSplit` non-zero for a bipartite run.
  virtual void runCell(const PairFilter& cell, std::span<const KeyBox> toDevice, std::size_t deviceSplit);
  /// Hands a sealed batch over (`toDevice`: its cells as the device gets
  /// them) and leaves `batch` empty, to be filled again; it may take the
  /// batch's storage while the device works on it.
  virtual void handOverBatch(Batch& batch, std::span<const std::span<const KeyBox>> toDevice) = 0;
  /// Returns once every answer is decoded; rethrows the first failure.
  virtual void finish() {}
  /// Returns once the device polls for the next hand-over (Polled only).
  virtual void awaken() {}

  /// The kind of `kind` on a device from `makeBackend`.
  static std::unique_ptr<HandOver> make(HandOvers kind, const BackendFactory& makeBackend, AnswerDecoder& decoder,
                                        HandOverTimer& timer);

 protected:
  HandOver(AnswerDecoder& decoder, HandOverTimer& timer) : decoder_(decoder), timer_(timer) {}
  static BackendTraits traitsOf(const Backend& backend);
  BackendTraits traits_;
  AnswerDecoder& decoder_;
  HandOverTimer& timer_;
};

/// Waits for each answer and decodes it, on the worker's thread.
class SynchronousHandOver final : public HandOver {
 public:
  /// On `backend`, which must outlive it.
  SynchronousHandOver(Backend& backend, AnswerDecoder& decoder, HandOverTimer& timer);
  /// On a backend of its own.
  SynchronousHandOver(std::unique_ptr<Backend> backend, AnswerDecoder& decoder, HandOverTimer& timer);
  void runCell(const PairFilter& cell, std::span<const KeyBox> toDevice, std::size_t deviceSplit) override;
  void handOverBatch(Batch& batch, std::span<const std::span<const KeyBox>> toDevice) override;

 private:
  // One hand-over: `run` fills the record's counters (timed as the device's),
  // then `decode` of its pairs (timed as host work), recorded.
  template <typename Run, typename Decode>
  void timed(Run&& run, Decode&& decode);

  std::unique_ptr<Backend> owned_;
  Backend& backend_;
  std::vector<Pair> local_;  // one hand-over's pairs, indices local to each cell
  std::vector<std::size_t> cellEnds_;
};

}  // namespace bpaccel
