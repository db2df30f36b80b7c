#include "rtl_backend.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "../cpu_backend.hpp"
#include "../model_backend.hpp"
#include "VBroadPhaseAccel.h"
#include "bpaccel_params.h"
#include "verilated.h"

namespace bpaccel {
namespace {

// Bit k of a result mask, whatever type Verilator chose for its width.
template <typename T>
bool maskBit(const T& mask, std::size_t k) {
  if constexpr (std::is_integral_v<T>) {
    return (static_cast<std::uint64_t>(mask) >> k) & 1u;
  } else {
    return (mask[k / 32] >> (k % 32)) & 1u;  // VlWide: 32-bit words
  }
}

void setBox(VBroadPhaseAccel& top, const KeyBox& b) {
  top.io_load_bits_min_0 = b.min[0];
  top.io_load_bits_min_1 = b.min[1];
  top.io_load_bits_min_2 = b.min[2];
  top.io_load_bits_max_0 = b.max[0];
  top.io_load_bits_max_1 = b.max[1];
  top.io_load_bits_max_2 = b.max[2];
}

// Appends the pairs of the beat on the result port to `out`. Bit k is the
// pair (iBase + k, jBase + k), both modulo 2^BPACCEL_INDEX_WIDTH: a short
// stream run's bases come moved down by its head pad and may wrap (its
// lanes below the pad never hit, so the pairs themselves do not).
void appendBeat(const VBroadPhaseAccel& top, std::vector<Pair>& out) {
  static_assert(BPACCEL_INDEX_WIDTH >= 1 && BPACCEL_INDEX_WIDTH < 32, "indices fit a 32-bit word");
  constexpr std::uint32_t indexMask = (1u << BPACCEL_INDEX_WIDTH) - 1;
  const std::uint32_t i0 = top.io_result_bits_iBase;
  const std::uint32_t j0 = top.io_result_bits_jBase;
  for (std::size_t k = 0; k < BPACCEL_M; ++k)
    if (maskBit(top.io_result_bits_mask, k))
      out.emplace_back((i0 + static_cast<std::uint32_t>(k)) & indexMask,
                       (j0 + static_cast<std::uint32_t>(k)) & indexMask);
}

// Adds the hardware's counters of its last run or batch to `stats`.
void addCounters(const VBroadPhaseAccel& top, RunStats& stats) {
  stats.loadCycles += top.io_counters_loadCycles;
  stats.cycles += top.io_counters_cycles;
  stats.issueCycles += top.io_counters_issueCycles;
  stats.stallCycles += top.io_counters_stallCycles;
  stats.hits += top.io_counters_hits;
}

}  // namespace

static_assert(BPACCEL_KEY_WIDTH >= 1 && BPACCEL_KEY_WIDTH <= 32,
              "the host's keys are 32 bits; narrower devices get narrowed keys (narrowKeys)");

RtlBackend::RtlBackend(std::function<bool(std::uint64_t)> consumerReady)
    : context_(std::make_unique<VerilatedContext>()),
      top_(std::make_unique<VBroadPhaseAccel>(context_.get(), "accel")),
      consumerReady_(consumerReady ? std::move(consumerReady) : [](std::uint64_t) { return true; }) {
  reset();
  // The header and the Verilated model must describe the same hardware.
  const auto check = [](const char* what, std::uint64_t model, std::uint64_t header) {
    if (model != header)
      throw std::runtime_error(
          fmt::format("rtl: Verilated model has {} = {} but bpaccel_params.h says {}; rebuild the host", what, model,
                      header));
  };
  check("architecture", top_->io_info_arch, BPACCEL_ARCH_ID);
  check("m", top_->io_info_m, BPACCEL_M);
  check("capacity", top_->io_info_capacity, BPACCEL_CAPACITY);
  check("key width", top_->io_info_keyWidth, BPACCEL_KEY_WIDTH);
  check("run overhead cycles", top_->io_info_runOverheadCycles, BPACCEL_RUN_OVERHEAD_CYCLES);
  check("read latency", top_->io_info_readLatency, BPACCEL_READ_LATENCY);
  check("batch cells", top_->io_info_batchCells, BPACCEL_BATCH_CELLS);
  check("cell tag width", top_->io_info_cellTagWidth, BPACCEL_CELL_TAG_WIDTH);
  check("batch overlaps loads", top_->io_info_batchOverlapsLoads, BPACCEL_BATCH_OVERLAPS_LOADS);
  check("bipartite runs", top_->io_info_bipartiteRuns, BPACCEL_BIPARTITE_RUNS);
}

RtlBackend::~RtlBackend() { top_->final(); }

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

void RtlBackend::settle() {
  top_->clock = 0;
  top_->eval();
}

void RtlBackend::tick() {
  top_->clock = 0;
  top_->eval();
  top_->clock = 1;
  top_->eval();
}

void RtlBackend::reset() {
  top_->io_load_valid = 0;
  top_->io_start_valid = 0;
  top_->io_cells_valid = 0;
  top_->io_result_ready = 0;
  top_->reset = 1;
  tick();
  tick();
  top_->reset = 0;
  settle();
}

void RtlBackend::run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) {
  runSplit(boxes, 0, out, stats);
}

void RtlBackend::runSplit(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                          RunStats& stats) {
  const std::size_t n = boxes.size();
  if (n > capacity())
    throw std::length_error(fmt::format("rtl: {} boxes exceed the hardware capacity {}", n, capacity()));
  checkKeyWidth(boxes);  // the ports would keep the low bits only
  const std::size_t before = out.size();
  try {
    runOnHardware(boxes, split, out, stats);
  } catch (...) {
    // A hang or a hardware error leaves the device mid-run: reset it so the
    // next batch starts from an idle accelerator, and drop this run's partial pairs.
    reset();
    out.resize(before);
    throw;
  }
}

void RtlBackend::runOnHardware(std::span<const KeyBox> boxes, std::size_t split, std::vector<Pair>& out,
                               RunStats& stats) {
  const std::size_t n = boxes.size();
  VBroadPhaseAccel& top = *top_;

  for (const KeyBox& b : boxes) {
    setBox(top, b);
    top.io_load_valid = 1;
    settle();
    if (!top.io_load_ready) throw std::runtime_error("rtl: load port not ready while idle");
    tick();
  }
  top.io_load_valid = 0;

  top.io_start_valid = 1;
  top.io_start_bits_count = static_cast<std::uint32_t>(n);
  top.io_start_bits_split = static_cast<std::uint32_t>(split);
  settle();
  if (!top.io_start_ready) throw std::runtime_error("rtl: start not accepted while idle");
  tick();
  top.io_start_valid = 0;

  // Play the consumer until the run is over. A bound far above any legal run
  // turns a hang into an error.
  const std::uint64_t issue = scheduleIssueCycles(n, BPACCEL_M, split);
  const std::uint64_t limit = 64 * (issue + 1000);
  const std::size_t before = out.size();
  std::uint64_t beats = 0;
  for (std::uint64_t cycle = 0;; ++cycle) {
    if (cycle > limit) throw std::runtime_error(fmt::format("rtl: run of {} boxes did not finish", n));
    const bool ready = consumerReady_(cycle);
    top.io_result_ready = ready;
    settle();
    if (!top.io_status_busy) break;
    if (ready && top.io_result_valid) {
      appendBeat(top, out);
      ++beats;
    }
    tick();
  }
  top.io_result_ready = 0;
  settle();
  if (!top.io_status_done) throw std::runtime_error("rtl: busy fell without done");
  if (top.io_status_error != BPACCEL_ERROR_NONE)
    throw std::runtime_error(fmt::format("rtl: hardware reported error code {}", top.io_status_error));
  if (top.io_counters_hits != out.size() - before)
    throw std::runtime_error(fmt::format("rtl: hardware counted {} hits but {} pairs arrived",
                                         top.io_counters_hits, out.size() - before));
  stats.runs += 1;
  stats.batches += 1;
  addCounters(top, stats);
  stats.boxesSent += n;
  stats.beatsReceived += beats;
}

void RtlBackend::runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                          std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  for (std::size_t k = 0; k < cells.size(); ++k)
    if (cells[k].size() > capacity())
      throw std::length_error(
          fmt::format("rtl: cell {} has {} boxes, above the hardware capacity {}", k, cells[k].size(), capacity()));
  checkSplits(cells, splits);
  for (std::size_t k = 0; k < cells.size(); ++k) {
    try {
      checkKeyWidth(cells[k]);  // the ports would keep the low bits only
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("{} (cell {} of the batch)", e.what(), k));
    }
  }
  const std::size_t pairsBefore = out.size();
  const std::size_t endsBefore = cellEnds.size();
  RunStats added;
  try {
    for (std::size_t first = 0; first < cells.size(); first += BPACCEL_BATCH_CELLS) {
      const std::size_t count = std::min<std::size_t>(BPACCEL_BATCH_CELLS, cells.size() - first);
      batchOnHardware(cells.subspan(first, count), splitsOf(splits, first, count), out, cellEnds, added);
    }
  } catch (...) {
    reset();
    out.resize(pairsBefore);
    cellEnds.resize(endsBefore);
    throw;
  }
  stats += added;
}

void RtlBackend::batchOnHardware(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                                 std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) {
  VBroadPhaseAccel& top = *top_;
  const std::size_t batchPairsBefore = out.size();
  std::uint64_t issue = 0, boxes = 0;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    issue += scheduleIssueCycles(cells[k].size(), BPACCEL_M, splitOf(splits, k));
    boxes += cells[k].size();
  }
  // A bound far above any legal batch turns a hang into an error.
  const std::uint64_t limit = 64 * (issue + boxes + 1000 * (cells.size() + 1));
  std::size_t nextCount = 0, cell = 0, box = 0;  // next count to push; cell and box being streamed
  std::size_t resultCell = 0;                     // the cell whose beats arrive now
  bool began = false;
  std::uint64_t beats = 0;
  for (std::uint64_t cycle = 0;; ++cycle) {
    if (cycle > limit) throw std::runtime_error(fmt::format("rtl: batch of {} cells did not finish", cells.size()));
    while (cell < cells.size() && box == cells[cell].size()) {
      ++cell;
      box = 0;
    }
    const bool countOffered = nextCount < cells.size();
    top.io_cells_valid = countOffered;
    if (countOffered) {
      top.io_cells_bits_count = static_cast<std::uint32_t>(cells[nextCount].size());
      top.io_cells_bits_split = static_cast<std::uint32_t>(splitOf(splits, nextCount));
    }
    const bool boxOffered = cell < cells.size();
    top.io_load_valid = boxOffered;
    if (boxOffered)
      setBox(top, cells[cell][box]);
    const bool ready = consumerReady_(cycle);
    top.io_result_ready = ready;
    settle();
    if (began && !countOffered && !boxOffered && !top.io_status_busy) break;
    if (countOffered && top.io_cells_ready) {
      began = true;
      ++nextCount;
    } else if (!began) {
      throw std::runtime_error("rtl: batch port not ready while idle");
    }
    if (boxOffered && top.io_load_ready) ++box;
    if (ready && top.io_result_valid) {
      // Beats arrive in cell order; a hardware batch never holds more cells than tags.
      const std::size_t tag = top.io_result_bits_cell;
      if (tag < resultCell || tag >= cells.size())
        throw std::runtime_error(fmt::format("rtl: beat of cell {} after cell {} of {}", tag, resultCell, cells.size()));
      for (; resultCell < tag; ++resultCell) cellEnds.push_back(out.size());
      appendBeat(top, out);
      ++beats;
    }
    tick();
  }
  for (; resultCell < cells.size(); ++resultCell) cellEnds.push_back(out.size());
  top.io_cells_valid = 0;
  top.io_load_valid = 0;
  top.io_result_ready = 0;
  settle();
  if (!top.io_status_done) throw std::runtime_error("rtl: the batch ended without done");
  if (top.io_status_error != BPACCEL_ERROR_NONE)
    throw std::runtime_error(fmt::format("rtl: hardware reported error code {} in a batch", top.io_status_error));
  if (top.io_status_cellsDone != cells.size())
    throw std::runtime_error(
        fmt::format("rtl: hardware ended {} cells of a batch of {}", top.io_status_cellsDone, cells.size()));
  if (top.io_counters_hits != out.size() - batchPairsBefore)
    throw std::runtime_error(fmt::format("rtl: hardware counted {} hits but {} pairs arrived in a batch",
                                         top.io_counters_hits, out.size() - batchPairsBefore));
  stats.runs += cells.size();
  stats.batches += 1;
  addCounters(top, stats);
  stats.boxesSent += boxes;
  stats.beatsReceived += beats;
}

}  // namespace bpaccel
