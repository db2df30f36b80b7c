// bpaccel: the host's command line.
//
//   bpaccel pairs --input FILE [--frame K] [--backend cpu|rtl|model] [--cell-size auto|C|none]
//                 [--partition auto|kd|grid] [--threads T] [--cells-per-batch K] [--repeat N] [--stats]
//   bpaccel convert --input FILE --output FILE [--frame K]
//
// FILE is a text box file or, named *.aabbs, a Broadmark scene. The benchmark
// has a program of its own (host/bench/tools/bpaccel_bench.cpp).

#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "bpaccel_params.h"
#include "broad_phase/broad_phase_config.hpp"
#include "commands.hpp"

namespace {

constexpr const char* kInputHelp =
    "Scene: a text file, one box a line ('minx miny minz maxx maxy maxz'; # comments), or a Broadmark "
    "scene (*.aabbs)";
constexpr const char* kFrameHelp = "Frame of a .aabbs scene: 0 (its initial frame, the default) to its frame count";
constexpr const char* kBackendHelp =
    "cpu: the answer, fast (software on every core); "
    "model: the device's cycle counts (its cycle-exact C++ model); "
    "rtl: to check the hardware itself (the Verilated AXI shell and core; slow)";

// "auto", "none" or a positive integer; the library's message as the option's error (exit code 2).
std::string checkCellSize(const std::string& text) {
  if (text == "auto") return {};
  try {
    bpaccel::parseCellSize(text);
  } catch (const std::invalid_argument&) {
    return "'" + text + "' is not auto, none or a positive integer";
  }
  return {};
}

CLI::App* addPairs(CLI::App& app, bpaccel::app::PairsOptions& o) {
  auto* cmd = app.add_subcommand("pairs", "Print every overlapping pair 'i j' (i < j, sorted) of a scene");
  cmd->add_option("--input", o.input, kInputHelp)->required();
  cmd->add_option("--frame", o.frame, kFrameHelp);
  cmd->add_option("--backend", o.backend, kBackendHelp)
      ->check(CLI::IsMember({"cpu", "model", "rtl"}))
      ->capture_default_str();
  cmd->add_option("--cell-size", o.cellSize,
                  "auto (chosen each frame), C (k-d: most boxes a leaf holds; grid: 2n/C cells) or none (one cell)")
      ->check(checkCellSize)
      ->capture_default_str();
  cmd->add_option("--partition", o.partition,
                  "How cells are made: auto (chosen each frame; with a cell size given, kd), kd (k-d tree, any "
                  "scene) or grid (uniform grid, near-uniform scenes; falls back to the tree when boxes would join "
                  "too many cells)")
      ->check(CLI::IsMember({"auto", "kd", "grid"}))
      ->capture_default_str();
  cmd->add_option("--threads", o.threads,
                  "Threads (0: every hardware thread with cpu, one device with rtl and model)")
      ->capture_default_str();
  cmd->add_option("--cells-per-batch", o.cellsPerBatch,
                  "Cells per hand-over to the device (the hardware's batch front end); 1: each on its own")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--repeat", o.repeat,
                  "Find the pairs this many times (frames on the same scene); --stats gives each host part's median")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_flag("--stats", o.stats, "Print the backend, threads, partition, cycles and timings to stderr");
  return cmd;
}

void addConvert(CLI::App& app, bpaccel::app::ConvertOptions& o) {
  auto* cmd = app.add_subcommand(
      "convert",
      "Convert a scene between the text box format and Broadmark's .aabbs (each file's format from its name). A "
      ".aabbs written from boxes holds them as its initial frame and its one step");
  cmd->add_option("--input", o.input, kInputHelp)->required();
  cmd->add_option("--output", o.output, "Scene to write: *.aabbs for Broadmark's format, else text")->required();
  cmd->add_option("--frame", o.frame, kFrameHelp);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Broad-phase collision detection: every overlapping pair of boxes, exactly. The default is the "
               "fastest exact answer here (the cpu backend on every core); the generated accelerator (m = " +
               std::to_string(BPACCEL_M) + ", capacity = " + std::to_string(BPACCEL_CAPACITY) +
               ") is one option away, --backend rtl or model"};
  app.require_subcommand(1);
  bpaccel::app::PairsOptions pairs;
  bpaccel::app::ConvertOptions convert;
  CLI::App* pairsCmd = addPairs(app, pairs);
  addConvert(app, convert);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Help prints and exits 0; every error of the command line is exit code 2.
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    return *pairsCmd ? bpaccel::app::runPairs(pairs) : bpaccel::app::runConvert(convert);
  } catch (const std::exception& e) {
    fmt::print(stderr, "bpaccel: {}\n", e.what());
    return 1;
  }
}
