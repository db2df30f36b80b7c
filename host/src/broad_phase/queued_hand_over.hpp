#pragma once
// The asynchronous hand-overs: the device on a thread of its own
// (AsyncBackend), up to kBatchesInFlight batches out at once.

#include <array>
#include <chrono>
#include <cstddef>
#include <future>
#include <span>

#include "../device/async_backend.hpp"
#include "../device/serial_stage.hpp"
#include "hand_over.hpp"

namespace bpaccel {

/// What both asynchronous kinds share: the device's thread, and a ring of
/// kBatchesInFlight slots, each a batch handed over with its answer to come.
class QueuedHandOver : public HandOver {
 protected:
  QueuedHandOver(const BackendFactory& makeBackend, std::chrono::microseconds devicePoll, AnswerDecoder& decoder,
                 HandOverTimer& timer);
  struct Slot {
    Batch batch;
    std::future<BatchResult> result;
    HandOverRecord record;
  };
  /// Hands `batch` over in the next slot, with its record, and takes the
  /// slot's storage for the next batch (the spans the device holds stay valid).
  Slot& submit(Batch& batch, std::span<const std::span<const KeyBox>> toDevice, const HandOverRecord& record);
  /// Decodes a slot's answer, waiting for it (its failure rethrown), and records it.
  void decodeAnswer(Slot& slot);
  Slot& slot(std::size_t handOver) { return slots_[handOver % kBatchesInFlight]; }

  std::size_t handedOver_ = 0;  // this frame's hand-overs
  // Before the device: the device's thread finishes with the slots' batches first.
  std::array<Slot, kBatchesInFlight> slots_;
  AsyncBackend async_;
};

/// A decoder thread waits for each answer and decodes it while the worker
/// goes on filling the next batch (HandOvers::Asynchronous).
class AsynchronousHandOver final : public QueuedHandOver {
 public:
  AsynchronousHandOver(const BackendFactory& makeBackend, AnswerDecoder& decoder, HandOverTimer& timer);
  void startFrame() override;
  void handOverBatch(Batch& batch, std::span<const std::span<const KeyBox>> toDevice) override;
  void finish() override;

 private:
  SerialStage decoding_;  // stopped (after its last task) before the slots and the device go
};

/// The worker decodes the answers itself, polling for one it must have; the
/// device's thread polls for hand-overs (HandOvers::Polled).
class PolledHandOver final : public QueuedHandOver {
 public:
  PolledHandOver(const BackendFactory& makeBackend, AnswerDecoder& decoder, HandOverTimer& timer);
  void startFrame() override;
  void handOverBatch(Batch& batch, std::span<const std::span<const KeyBox>> toDevice) override;
  void finish() override;
  void awaken() override;

 private:
  // The oldest hand-over not yet decoded, polled for until it has arrived;
  // then decoded (its failure rethrown).
  void decodeOldest();
  // Decodes, in order, the hand-overs whose answers have arrived.
  void decodeArrived();
  // Waits out the hand-overs a failed frame left with the device, whose
  // answers nobody will decode (their batches' storage is reused).
  void abandonOutstanding();

  std::size_t decoded_ = 0;  // this frame's hand-overs decoded, in order
};

}  // namespace bpaccel
