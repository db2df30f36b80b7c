#include "rtl_backend.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "../cpu_backend.hpp"
#include "../model_backend.hpp"
#include "bpaccel_params.h"

namespace bpaccel {
namespace {

// The run statistics of one CELLS command, from its trailer: the core's own counters.
RunStats statsOf(const Trailer& t) {
  RunStats s;
  s.runs = t.cells;
  s.batches = 1;
  s.loadCycles = t.intakeCycles;
  s.cycles = t.runCycles();
  s.issueCycles = t.issueCycles;
  s.stallCycles = t.stallCycles;
  s.hits = t.pairs;
  s.boxesSent = t.boxes;
  s.beatsReceived = t.records;
  return s;
}

}  // namespace

static_assert(BPACCEL_KEY_WIDTH >= 1 && BPACCEL_KEY_WIDTH <= 32,
              "the host's keys are 32 bits; narrower devices get narrowed keys (narrowKeys)");

RtlBackend::RtlBackend(std::function<bool(std::uint64_t)> replyReady)
    : RtlBackend(RtlBackendConfig{.shell = {.replyReady = std::move(replyReady)}}) {}

RtlBackend::RtlBackend(RtlBackendConfig config)
    : transport_(std::make_unique<VerilatedShellTransport>(std::move(config.shell))),
      driver_(std::make_unique<ShellDriver>(*transport_, config.driver)) {}

RtlBackend::~RtlBackend() = default;

std::size_t RtlBackend::capacity() const { return BPACCEL_CAPACITY; }
std::size_t RtlBackend::lanes() { return BPACCEL_M; }
std::size_t RtlBackend::batchCells() { return BPACCEL_BATCH_CELLS; }
std::uint64_t RtlBackend::runOverheadCycles() { return BPACCEL_RUN_OVERHEAD_CYCLES; }
std::string RtlBackend::architecture() { return BPACCEL_ARCH; }
bool RtlBackend::bipartite() const { return BPACCEL_BIPARTITE_RUNS != 0; }
unsigned RtlBackend::keyWidth() const { return BPACCEL_KEY_WIDTH; }

std::unique_ptr<Backend> makeBuiltBackend(const std::string& name) {
  if (name == "rtl") return std::make_unique<RtlBackend>();
  if (name == "model") return std::make_unique<ModelBackend>(builtDeviceParams());
  if (name == "cpu") return std::make_unique<CpuBackend>();
  throw std::invalid_argument(fmt::format("no backend named '{}' (rtl, model or cpu)", name));
}

void RtlBackend::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) {
  runSplit(boxes, 0, out, stats);
}

void RtlBackend::runSplit(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                          RunStats& stats) {
  if (boxes.size() > capacity())
    throw std::length_error(fmt::format("rtl: {} boxes exceed the hardware capacity {}", boxes.size(), capacity()));
  checkKeyWidth(boxes);
  const std::span<const KeyBox> cells[] = {boxes};
  const std::size_t splits[] = {split};
  std::vector<std::size_t> ends;
  runCommands({cells, splits}, out, ends, stats);
}

void RtlBackend::checkCells(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits) const {
  for (std::size_t k = 0; k < cells.size(); ++k)
    if (cells[k].size() > capacity())
      throw std::length_error(
          fmt::format("rtl: cell {} has {} boxes, above the hardware capacity {}", k, cells[k].size(), capacity()));
  checkSplits(cells, splits);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    try {
      checkKeyWidth(cells[k]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("{} (cell {} of the batch)", e.what(), k));
    }
  }
}

void RtlBackend::runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                          std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  checkCells(cells, splits);
  runCommands({cells, splits}, out, cellEnds, stats);
}

void RtlBackend::runCommands(const CellsCommand& all, std::vector<Pair>& out, std::vector<std::size_t>& cellEnds,
                             RunStats& stats) {
  // Commands of at most a hardware batch each: the core's batches, as the model counts them.
  const std::size_t pairsBefore = out.size(), endsBefore = cellEnds.size();
  RunStats added;
  try {
    for (std::size_t first = 0; first < all.cells.size(); first += BPACCEL_BATCH_CELLS) {
      const std::size_t count = std::min<std::size_t>(BPACCEL_BATCH_CELLS, all.cells.size() - first);
      const CellsCommand command{all.cells.subspan(first, count), splitsOf(all.splits, first, count)};
      added += statsOf(driver_->runCells(command, out, cellEnds));
    }
  } catch (...) {
    out.resize(pairsBefore);
    cellEnds.resize(endsBefore);
    throw;
  }
  stats += added;
}

}  // namespace bpaccel
