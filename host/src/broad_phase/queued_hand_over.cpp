#include "queued_hand_over.hpp"

#include <stdexcept>
#include <utility>

namespace bpaccel {
namespace {

// A device from the factory, refused if there is none.
BackendFactory checked(const BackendFactory& makeBackend) {
  return [&makeBackend] {
    auto device = makeBackend();
    if (!device) throw std::invalid_argument("broad phase: the backend factory gave no backend");
    return device;
  };
}

}  // namespace

QueuedHandOver::QueuedHandOver(const BackendFactory& makeBackend, std::chrono::microseconds devicePoll,
                               AnswerDecoder& decoder, HandOverTimer& timer)
    : HandOver(decoder, timer), async_(checked(makeBackend), devicePoll) {
  traits_ = {async_.name(), async_.capacity(), async_.bipartite(), async_.keyWidth()};
}

QueuedHandOver::Slot& QueuedHandOver::submit(Batch& batch, std::span<const std::span<const KeyBox>> toDevice,
                                             const HandOverRecord& record) {
  Slot& s = slot(handedOver_++);
  s.result = async_.submit(toDevice, batch.splits);
  // Swapping keeps the vectors' storage, so the spans the device holds stay
  // valid; `batch` takes the decoded batch's storage.
  std::swap(batch, s.batch);
  batch.clear();
  s.record = record;
  return s;
}

void QueuedHandOver::decodeAnswer(Slot& s) {
  BatchResult result = s.result.get();  // rethrows the device's failure
  const auto got = timer_.now();
  decoder_.addStats(result.stats);
  decoder_.decodeBatch(s.batch, result.pairs, result.cellEnds, traits_.name);
  s.record.stats = result.stats;
  s.record.decodeSeconds = FrameClock::seconds(got, timer_.now());
  timer_.record(s.record);
}

AsynchronousHandOver::AsynchronousHandOver(const BackendFactory& makeBackend, AnswerDecoder& decoder,
                                           HandOverTimer& timer)
    : QueuedHandOver(makeBackend, std::chrono::microseconds{}, decoder, timer), decoding_(kBatchesInFlight) {}

// Left over only if a frame failed before its end: the device and the decoder
// must be done with those batches first (before the worker's pairs are
// cleared, which the decoder writes). Their failure was the failed frame's.
void AsynchronousHandOver::startFrame() {
  try {
    decoding_.drain();
  } catch (...) {
  }
  handedOver_ = 0;
}

// The batch goes to the device and its decoding to the decoder thread, which
// waits for the device's answer; the worker goes on filling the next batch at
// once. With kBatchesInFlight batches handed over and not yet decoded, it
// waits for the oldest to be decoded, whose slot (and storage) this batch
// takes: time waiting for the device, not host work.
void AsynchronousHandOver::handOverBatch(Batch& batch, std::span<const std::span<const KeyBox>> toDevice) {
  if (decoding_.failed()) {
    batch.clear();
    decoding_.drain();  // rethrows the device's or the decoding's failure: the frame stops here
  }
  const auto ready = timer_.now();
  HandOverRecord record;
  record.readySeconds = timer_.readySeconds(ready);
  decoding_.waitForRoom();
  timer_.addBackendTimeSince(ready);
  Slot& s = submit(batch, toDevice, record);
  decoding_.post([this, &s] { decodeAnswer(s); });
}

void AsynchronousHandOver::finish() {
  const auto waitFrom = timer_.now();
  decoding_.drain();  // every batch decoded; rethrows the first failure
  timer_.addBackendTimeSince(waitFrom);
}

PolledHandOver::PolledHandOver(const BackendFactory& makeBackend, AnswerDecoder& decoder, HandOverTimer& timer)
    : QueuedHandOver(makeBackend, kDevicePollMicroseconds, decoder, timer) {}

void PolledHandOver::startFrame() {
  abandonOutstanding();
  async_.wake();  // polling by the time the partition has the first batch
  handedOver_ = 0;
  decoded_ = 0;
}

void PolledHandOver::awaken() { async_.awaken(); }

// The batch goes to the device, and the answers that have arrived are decoded
// here before the worker goes on; with kBatchesInFlight batches handed over
// and not yet decoded, it first polls for the oldest's answer (time waiting
// for the device, not host work) and decodes it.
void PolledHandOver::handOverBatch(Batch& batch, std::span<const std::span<const KeyBox>> toDevice) {
  HandOverRecord record;
  record.readySeconds = timer_.readySeconds(timer_.now());
  if (handedOver_ - decoded_ == kBatchesInFlight) decodeOldest();
  submit(batch, toDevice, record);
  decodeArrived();
}

void PolledHandOver::finish() {
  while (decoded_ < handedOver_) decodeOldest();
}

void PolledHandOver::decodeOldest() {
  Slot& s = slot(decoded_);
  const auto from = FrameClock::Clock::now();
  // Polled for, as the device's thread polls for hand-overs: sleeping on the
  // future would cost a wake-up when it is set. Beyond kDevicePollMicroseconds
  // (a long run, or more polling threads than cores) it sleeps after all.
  while (s.result.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    if (FrameClock::Clock::now() - from > kDevicePollMicroseconds) {
      s.result.wait();
      break;
    }
    pollPause();
  }
  timer_.addBackendTimeSince(from);
  ++decoded_;  // first: a failure leaves the next one the oldest
  decodeAnswer(s);
}

void PolledHandOver::decodeArrived() {
  while (decoded_ < handedOver_ && slot(decoded_).result.wait_for(std::chrono::seconds(0)) == std::future_status::ready)
    decodeOldest();
}

void PolledHandOver::abandonOutstanding() {
  for (; decoded_ < handedOver_; ++decoded_) {
    auto& result = slot(decoded_).result;
    if (result.valid()) result.wait();
  }
}

}  // namespace bpaccel
