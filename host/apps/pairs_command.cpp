#include <algorithm>
#include <cstdio>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "broad_phase/broad_phase.hpp"
#include "broad_phase/frame_observer.hpp"
#include "commands.hpp"
#include "core/median.hpp"
#include "device/rtl/rtl_backend.hpp"
#include "scene_files.hpp"

namespace bpaccel::app {

namespace {

/// --cell-size: "auto", "none" or a positive integer.
CellSize cellSizeOf(const std::string& text) {
  return text == "auto" ? CellSize::automatic() : CellSize(parseCellSize(text));
}

/// --threads 0: every hardware thread for the software backend; one device for the hardware's.
std::size_t threadsOf(const PairsOptions& o) {
  if (o.threads != 0) return o.threads;
  return o.backend == "cpu" ? std::max(1u, std::thread::hardware_concurrency()) : 1;
}

/// Each part's host time per repetition; --stats prints their medians.
struct PartTimes {
  std::vector<double> convert, partition, cells, total, host;
  void add(const HostTimes& t) {
    convert.push_back(t.convertSeconds);
    partition.push_back(t.partitionSeconds);
    cells.push_back(t.cellsSeconds);
    total.push_back(t.totalSeconds);
    host.push_back(t.totalSeconds - t.backendSeconds);
  }
};

void printPairs(std::vector<Pair>& pairs) {
  std::sort(pairs.begin(), pairs.end());
  std::string text;
  text.reserve(pairs.size() * 12);
  for (const auto& [i, j] : pairs) fmt::format_to(std::back_inserter(text), "{} {}\n", i, j);
  std::fwrite(text.data(), 1, text.size(), stdout);
}

void printStats(const PairsOptions& o, const BroadPhase& phase, std::size_t objects, std::size_t pairs,
                const PartTimes& t) {
  const auto& s = phase.stats();
  const CellChoice& choice = phase.choice();
  const bool autoSize = phase.config().cellSize.isAutomatic();
  const bool autoKind = autoSize && phase.config().partition == PartitionKind::Automatic;
  fmt::print(stderr,
             "backend {} threads {} cell-size {}{} partition {}{} objects {} pairs {}\n"
             "runs {} batches {} cycles {} issue-cycles {} stall-cycles {} hits {} boxes-sent {} beats {}\n"
             "host seconds (measured): convert {:.6f} partition {:.6f} cells {:.6f} total {:.6f} "
             "host-without-backend {:.6f} (median of {} frames)\n",
             o.backend, phase.threads(), cellSizeName(choice.cellSize), autoSize ? " (auto)" : "",
             choice.cellSize ? std::string(phase.partition().name()) : "none", autoKind ? " (auto)" : "", objects,
             pairs, s.runs, s.batches, s.cycles, s.issueCycles, s.stallCycles, s.hits, s.boxesSent, s.beatsReceived,
             median(t.convert), median(t.partition), median(t.cells), median(t.total), median(t.host), o.repeat);
  if (!choice.cellSize) return;
  const CellOccupancy c = occupancyOf(phase.partition(), objects);
  fmt::print(stderr, "cells {} entries {} entries-per-box {:.3f} mean-cell {:.1f}\n", c.cells, c.entries,
             c.entriesPerBox(), c.meanCell());
}

std::unique_ptr<BroadPhase> makeBroadPhase(const PairsOptions& o, const BroadPhaseConfig& config,
                                           std::unique_ptr<Backend>& single) {
  if (config.threads == 1) {
    single = makeBuiltBackend(o.backend);
    return std::make_unique<BroadPhase>(*single, config);
  }
  const std::string name = o.backend;
  return std::make_unique<BroadPhase>([name] { return makeBuiltBackend(name); }, config);
}

}  // namespace

int runPairs(const PairsOptions& o) {
  std::vector<Aabb> boxes;
  try {
    boxes = readSceneFile(o.input, o.frame);
  } catch (const SceneFileError& e) {
    fmt::print(stderr, "bpaccel: {}\n", e.what());
    return e.exitCode();
  }
  // --stats times each part of the host's work (the clock is read only then).
  LastFrameTiming timing;
  const BroadPhaseConfig config{.cellSize = cellSizeOf(o.cellSize),
                                .partition = parsePartitionKind(o.partition),
                                .threads = threadsOf(o),
                                .cellsPerBatch = o.cellsPerBatch,
                                .observer = o.stats ? &timing : nullptr};
  std::unique_ptr<Backend> backend;
  const std::unique_ptr<BroadPhase> phase = makeBroadPhase(o, config, backend);
  std::vector<Pair> pairs;
  PartTimes times;
  for (std::size_t r = 0; r < o.repeat; ++r) {
    phase->findPairs(boxes, pairs);
    times.add(timing.times());
  }
  printPairs(pairs);
  if (o.stats) printStats(o, *phase, boxes.size(), pairs.size(), times);
  return 0;
}

}  // namespace bpaccel::app
