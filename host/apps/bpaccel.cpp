// bpaccel: the host's command line: the overlapping pairs of a box file.
//
//   bpaccel pairs --input FILE [--backend rtl|model|cpu] [--cell-size C|none] [--partition kd|grid] [--stats]
//
// The benchmark has a program of its own (host/bench/tools/bpaccel_bench.cpp).

#include <algorithm>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ostream.h>

#include "device/backend.hpp"
#include "core/box_file.hpp"
#include "bpaccel_params.h"
#include "broad_phase/broad_phase.hpp"
#include "core/keys.hpp"
#include "core/median.hpp"
#include "device/rtl/rtl_backend.hpp"

namespace {

// The library's parse, as the option's validation error (exit code 2).
std::optional<std::size_t> parseCellSize(const std::string& text) {
  try {
    return bpaccel::parseCellSize(text);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--cell-size", e.what());
  }
}

int runPairs(const std::string& input, const std::string& backendName, const std::string& cellSizeText,
             bpaccel::PartitionKind partition, std::size_t cellsPerBatch, std::size_t repeat, bool stats) {
  std::ifstream file(input);
  if (!file) {
    fmt::print(stderr, "bpaccel: cannot open '{}'\n", input);
    return 2;
  }
  std::vector<bpaccel::Aabb> boxes;
  try {
    boxes = bpaccel::readBoxes(file);
  } catch (const bpaccel::ParseError& e) {
    fmt::print(stderr, "bpaccel: {}:{}\n", input, e.what());
    return 1;
  }
  auto backend = bpaccel::makeBuiltBackend(backendName);
  // --stats times each part of the host's work (the clock is read only then).
  bpaccel::LastFrameTiming timing;
  bpaccel::BroadPhase broadPhase(*backend, {.cellSize = parseCellSize(cellSizeText),
                                            .partition = partition,
                                            .cellsPerBatch = cellsPerBatch,
                                            .observer = stats ? &timing : nullptr});
  std::vector<bpaccel::Pair> pairs;
  // Each part's host time per repetition; --stats prints their medians.
  std::vector<double> convert, partitionTime, cells, total, host;
  for (std::size_t r = 0; r < repeat; ++r) {
    broadPhase.findPairs(boxes, pairs);
    const auto& t = timing.times();
    convert.push_back(t.convertSeconds);
    partitionTime.push_back(t.partitionSeconds);
    cells.push_back(t.cellsSeconds);
    total.push_back(t.totalSeconds);
    host.push_back(t.totalSeconds - t.backendSeconds);
  }
  std::sort(pairs.begin(), pairs.end());

  std::string text;
  text.reserve(pairs.size() * 12);
  for (const auto& [i, j] : pairs) fmt::format_to(std::back_inserter(text), "{} {}\n", i, j);
  std::fwrite(text.data(), 1, text.size(), stdout);

  if (stats) {
    const auto& s = broadPhase.stats();
    fmt::print(stderr,
               "backend {} cell-size {} partition {} objects {} pairs {}\n"
               "runs {} batches {} cycles {} issue-cycles {} stall-cycles {} hits {} boxes-sent {} beats {}\n"
               "host seconds (measured): convert {:.6f} partition {:.6f} cells {:.6f} total {:.6f} "
               "host-without-backend {:.6f} (median of {} frames)\n",
               backend->name(), cellSizeText, broadPhase.partition().name(), boxes.size(), pairs.size(), s.runs,
               s.batches, s.cycles, s.issueCycles, s.stallCycles, s.hits, s.boxesSent, s.beatsReceived,
               bpaccel::median(convert), bpaccel::median(partitionTime), bpaccel::median(cells),
               bpaccel::median(total), bpaccel::median(host), repeat);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Broad-phase collision detection on the generated accelerator (m = " + std::to_string(BPACCEL_M) +
               ", capacity = " + std::to_string(BPACCEL_CAPACITY) + ")"};
  app.require_subcommand(1);

  std::string input, backendName = "rtl", cellSize = "none";
  bool stats = false;
  auto* pairs = app.add_subcommand("pairs", "Print every overlapping pair 'i j' (i < j, sorted) of a box file");
  pairs->add_option("--input", input, "Text file: one box a line, 'minx miny minz maxx maxy maxz'; # comments")
      ->required();
  pairs->add_option("--backend", backendName, "rtl (Verilated hardware), model (its C++ model) or cpu (software)")
      ->check(CLI::IsMember({"rtl", "model", "cpu"}))
      ->capture_default_str();
  pairs->add_option("--cell-size", cellSize,
                    "Cell size C (k-d: most boxes a leaf holds; grid: 2n/C cells) or 'none' (one cell)")
      ->capture_default_str();
  std::string partitionName = "kd";
  pairs->add_option("--partition", partitionName,
                    "How cells are made: kd (k-d tree, any scene) or grid (uniform grid, near-uniform scenes; "
                    "falls back to the tree when boxes would join too many cells)")
      ->check(CLI::IsMember({"kd", "grid"}))
      ->capture_default_str();
  std::size_t pairsCellsPerBatch = 1;
  pairs->add_option("--cells-per-batch", pairsCellsPerBatch,
                    "Cells per hand-over to the backend (the hardware's batch front end); 1: each on its own")
      ->check(CLI::PositiveNumber)->capture_default_str();
  pairs->add_flag("--stats", stats, "Print cycles and timings to stderr");
  std::size_t repeat = 1;
  pairs->add_option("--repeat", repeat,
                    "Find the pairs this many times (frames on the same scene); --stats gives each host part's median")
      ->check(CLI::PositiveNumber)->capture_default_str();

  CLI11_PARSE(app, argc, argv);
  try {
    parseCellSize(cellSize);
    return runPairs(input, backendName, cellSize, bpaccel::parsePartitionKind(partitionName), pairsCellsPerBatch,
                    repeat, stats);
  } catch (const CLI::ValidationError& e) {
    fmt::print(stderr, "bpaccel: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "bpaccel: {}\n", e.what());
    return 1;
  }
}
