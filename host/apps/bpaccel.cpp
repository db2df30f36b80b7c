// bpaccel: command-line front end of the host.
//
//   bpaccel pairs --input FILE [--backend rtl|model|cpu] [--cell-size C|none] [--stats]

#include <algorithm>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ostream.h>

#include "backend.hpp"
#include "box_file.hpp"
#include "bpaccel_params.h"
#include "broad_phase.hpp"
#include "keys.hpp"
#include "rtl_backend.hpp"

namespace {

std::unique_ptr<bpaccel::Backend> makeBackend(const std::string& name) {
  if (name == "rtl") return std::make_unique<bpaccel::RtlBackend>();
  if (name == "model")
    return std::make_unique<bpaccel::ModelBackend>(BPACCEL_M, BPACCEL_CAPACITY, BPACCEL_RUN_OVERHEAD_CYCLES);
  return std::make_unique<bpaccel::CpuBackend>();
}

std::optional<std::size_t> parseCellSize(const std::string& text) {
  if (text == "none") return std::nullopt;
  std::size_t pos = 0;
  unsigned long long v = 0;
  try {
    v = std::stoull(text, &pos);
  } catch (const std::exception&) {
    pos = 0;
  }
  if (pos != text.size() || v < 1 || text.front() == '-')
    throw CLI::ValidationError("--cell-size", fmt::format("'{}' is neither a positive integer nor 'none'", text));
  return static_cast<std::size_t>(v);
}

int runPairs(const std::string& input, const std::string& backendName, const std::string& cellSizeText, bool stats) {
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
  auto backend = makeBackend(backendName);
  bpaccel::BroadPhase broadPhase(*backend, parseCellSize(cellSizeText));
  std::vector<bpaccel::Pair> pairs;
  broadPhase.findPairs(boxes, pairs);
  std::sort(pairs.begin(), pairs.end());

  std::string text;
  text.reserve(pairs.size() * 12);
  for (const auto& [i, j] : pairs) fmt::format_to(std::back_inserter(text), "{} {}\n", i, j);
  std::fwrite(text.data(), 1, text.size(), stdout);

  if (stats) {
    const auto& s = broadPhase.stats();
    const auto& t = broadPhase.times();
    fmt::print(stderr,
               "backend {} cell-size {} objects {} pairs {}\n"
               "runs {} cycles {} issue-cycles {} stall-cycles {} hits {} boxes-sent {} beats {}\n"
               "host seconds (measured): convert {:.6f} tree {:.6f} cells {:.6f} total {:.6f}\n",
               backend->name(), cellSizeText, boxes.size(), pairs.size(), s.runs, s.cycles, s.issueCycles,
               s.stallCycles, s.hits, s.boxesSent, s.beatsReceived, t.convertSeconds, t.treeSeconds,
               t.cellsSeconds, t.totalSeconds + t.convertSeconds);
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
  pairs->add_option("--cell-size", cellSize, "k-d tree cell size C (most boxes a leaf holds) or 'none'")
      ->capture_default_str();
  pairs->add_flag("--stats", stats, "Print cycles and timings to stderr");

  CLI11_PARSE(app, argc, argv);
  try {
    parseCellSize(cellSize);
    return runPairs(input, backendName, cellSize, stats);
  } catch (const CLI::ValidationError& e) {
    fmt::print(stderr, "bpaccel: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "bpaccel: {}\n", e.what());
    return 1;
  }
}
