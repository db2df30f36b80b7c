#include "hand_over.hpp"

#include <stdexcept>
#include <utility>

#include "queued_hand_over.hpp"

namespace bpaccel {

BackendTraits HandOver::traitsOf(const Backend& backend) {
  return {backend.name(), backend.capacity(), backend.bipartite(), backend.keyWidth()};
}

void HandOver::runCell(const PairFilter&, std::span<const KeyBox>, std::size_t) {
  throw std::logic_error("broad phase: only synchronous hand-overs run cells one by one");
}

std::unique_ptr<HandOver> HandOver::make(HandOvers kind, const BackendFactory& makeBackend, AnswerDecoder& decoder,
                                         HandOverTimer& timer) {
  switch (kind) {
    case HandOvers::Asynchronous: return std::make_unique<AsynchronousHandOver>(makeBackend, decoder, timer);
    case HandOvers::Polled: return std::make_unique<PolledHandOver>(makeBackend, decoder, timer);
    case HandOvers::Synchronous: break;
  }
  auto backend = makeBackend();
  if (!backend) throw std::invalid_argument("broad phase: the backend factory gave no backend");
  return std::make_unique<SynchronousHandOver>(std::move(backend), decoder, timer);
}

SynchronousHandOver::SynchronousHandOver(Backend& backend, AnswerDecoder& decoder, HandOverTimer& timer)
    : HandOver(decoder, timer), backend_(backend) {
  traits_ = traitsOf(backend_);
}

SynchronousHandOver::SynchronousHandOver(std::unique_ptr<Backend> backend, AnswerDecoder& decoder,
                                         HandOverTimer& timer)
    : HandOver(decoder, timer), owned_(std::move(backend)), backend_(*owned_) {
  traits_ = traitsOf(backend_);
}

void SynchronousHandOver::runCell(const PairFilter& cell, std::span<const KeyBox> toDevice, std::size_t deviceSplit) {
  local_.clear();
  timed(
      [&](RunStats& stats) {
        if (deviceSplit == 0)
          backend_.run(toDevice, local_, stats);
        else
          backend_.runBipartite(toDevice, deviceSplit, local_, stats);
      },
      [&] { decoder_.decodeCell(cell, local_); });
}

void SynchronousHandOver::handOverBatch(Batch& batch, std::span<const std::span<const KeyBox>> toDevice) {
  local_.clear();
  cellEnds_.clear();
  timed([&](RunStats& stats) { backend_.runBatch(toDevice, batch.splits, local_, cellEnds_, stats); },
        [&] { decoder_.decodeBatch(batch, local_, cellEnds_, traits_.name); });
  batch.clear();
}

template <typename Run, typename Decode>
void SynchronousHandOver::timed(Run&& run, Decode&& decode) {
  HandOverRecord record;
  const auto ready = timer_.now();
  record.readySeconds = timer_.readySeconds(ready);
  run(record.stats);
  const auto ran = timer_.now();
  timer_.addBackendTime(ready, ran);
  decoder_.addStats(record.stats);
  decode();
  record.decodeSeconds = FrameClock::seconds(ran, timer_.now());
  timer_.record(record);
}

}  // namespace bpaccel
