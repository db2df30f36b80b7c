// bpaccel: command-line front end of the host.
//
//   bpaccel pairs --input FILE [--backend rtl|model|cpu] [--cell-size C|none] [--partition kd|grid] [--stats]

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ostream.h>

#include <nlohmann/json.hpp>

#include "backend.hpp"
#include "benchmark.hpp"
#include "scene.hpp"
#include "box_file.hpp"
#include "bpaccel_params.h"
#include "broad_phase.hpp"
#include "keys.hpp"
#include "rtl_backend.hpp"

namespace {

std::unique_ptr<bpaccel::Backend> makeBackend(const std::string& name) {
  if (name == "rtl") return std::make_unique<bpaccel::RtlBackend>();
  if (name == "model")
    return std::make_unique<bpaccel::ModelBackend>(bpaccel::modelOfBuiltHardware());  // this build's architecture
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

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : (v[(v.size() - 1) / 2] + v[v.size() / 2]) / 2;
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
  auto backend = makeBackend(backendName);
  bpaccel::BroadPhase broadPhase(*backend, parseCellSize(cellSizeText), cellsPerBatch, partition);
  std::vector<bpaccel::Pair> pairs;
  // Each part's host time per repetition; --stats prints their medians.
  std::vector<double> convert, partitionTime, cells, total, host;
  for (std::size_t r = 0; r < repeat; ++r) {
    broadPhase.findPairs(boxes, pairs);
    const auto& t = broadPhase.times();
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
               median(convert), median(partitionTime), median(cells), median(total), median(host), repeat);
  }
  return 0;
}

// The device the accelerator methods model: this program's Verilated configuration.
std::shared_ptr<bpaccel::DeviceConfig> makeDevice(const std::string& backend, double clockMHz,
                                                  const std::string& fpgaReport, double linkGBytesPerSecond,
                                                  double linkLatencyUs, std::size_t cellsPerBatch,
                                                  std::size_t firstBatchCells, bool paced) {
  auto device = std::make_shared<bpaccel::DeviceConfig>();
  device->backend = backend;
  device->makeBackend = [backend] { return makeBackend(backend); };
  device->beatBytes = bpaccel::resultBeatBytesOfBuiltHardware();
  device->link.bytesPerBox = static_cast<double>(bpaccel::loadBoxBytesOfBuiltHardware());
  device->hardware = {{"m", BPACCEL_M},
                      {"capacity", BPACCEL_CAPACITY},
                      {"key_width", BPACCEL_KEY_WIDTH},
                      {"run_overhead_cycles", BPACCEL_RUN_OVERHEAD_CYCLES},
                      {"fingerprint", BPACCEL_FINGERPRINT}};
  if (clockMHz > 0) {
    device->clockHz = clockMHz * 1e6;
    device->clockSource = fmt::format("--clock-mhz {}", clockMHz);
  } else {
    auto clock = bpaccel::clockFromFpgaReport(fpgaReport, BPACCEL_M, BPACCEL_ARCH, BPACCEL_KEY_WIDTH);
    device->clockHz = clock.hz;
    device->clockSource = std::move(clock.source);
  }
  device->link.bandwidthBytesPerSecond = linkGBytesPerSecond * 1e9;
  device->link.latencySecondsPerRun = linkLatencyUs * 1e-6;
  device->cellsPerBatch = cellsPerBatch;
  device->firstBatchCells = firstBatchCells;
  device->paced = paced && cellsPerBatch > 1;  // one cell a hand-over has nothing to overlap
  device->hardware["batch_cells"] = BPACCEL_BATCH_CELLS;
  return device;
}

int runBench(const bpaccel::BenchConfig& config, bpaccel::LineUpConfig lineUp, const std::vector<std::string>& cells,
             const std::string& jsonPath) {
  lineUp.cellSizes.clear();
  for (const auto& c : cells) lineUp.cellSizes.push_back(parseCellSize(c));
  fmt::print(stderr, "bench: clock {}\n", lineUp.device->clockSource);
  bpaccel::Benchmark bench(config, bpaccel::standardLineUp(lineUp), bpaccel::describe(lineUp),
                           [](const std::string& line) { fmt::print(stderr, "bench: {}\n", line); });
  nlohmann::json results;
  try {
    results = bench.run();
  } catch (const bpaccel::ValidationFailure& e) {
    fmt::print(stderr, "bench: VALIDATION FAILED: {}\n", e.what());
    return 3;
  }
  const std::filesystem::path path(jsonPath);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << results.dump(2) << "\n";
  fmt::print("{}", bpaccel::Benchmark::table(results));
  fmt::print("\nAll frames validated. Results: {}\n", jsonPath);
  for (const auto& r : results["rows"])
    for (const auto& m : r["methods"])
      if (m["missing_pairs"].is_number() && m["missing_pairs"].get<std::uint64_t>() > 0)
        fmt::print(stderr, "bench: FINDING: {} missed {} exact pairs at n = {} (marked in the table)\n",
                   m["name"].get<std::string>(), m["missing_pairs"].get<std::uint64_t>(),
                   r["objects"].get<std::size_t>());
  return 0;
}

int runScene(const bpaccel::SceneConfig& config, std::size_t frames, const std::string& out) {
  bpaccel::BouncingCubeScene scene(config);
  for (std::size_t f = 0; f < frames; ++f) scene.step();
  nlohmann::json j;
  j["cube_edge"] = scene.cubeEdge();
  j["frame"] = frames;
  j["objects"] = nlohmann::json::array();
  for (const auto& p : scene.poses())
    j["objects"].push_back({{"shape", p.shape}, {"position", p.position}, {"rotation", p.rotation},
                            {"half_extents", p.halfExtents}});
  const std::filesystem::path path(out);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << j.dump(1) << "\n";
  fmt::print(stderr, "scene: wrote {} objects after {} frames to {}\n", scene.size(), frames, out);
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

  bpaccel::BenchConfig bench;
  bench.wholeStepObjects = 8000;
  bpaccel::LineUpConfig lineUp;
  lineUp.cpuThreads = std::thread::hardware_concurrency();
  std::vector<std::string> benchCells = {"none", "16", "32", "64", "128", "256"};
  std::string benchBackend = "rtl", benchJson = "results/bench.json";
  double clockMHz = 0, linkGBytesPerSecond = 4, linkLatencyUs = 1;
  // As many cells a hand-over as the batch front end queues (its count
  // queue's depth): measured against 16 (grid 64, 8000 objects, model), the
  // serial frame fell by about 4 % (fewer first cells loaded in series and
  // fewer link latencies) and the overlapped frame did not move.
  std::size_t cellsPerBatch = BPACCEL_BATCH_CELLS;
  // Slow start: the device starts after a frame's first 4 cells, not 64.
  // Measured with frame_timing (8000 objects, model, paired frame by frame):
  // the modelled overlapped frame fell by 3 % at grid 64 and 4 % at grid 128
  // (first hand-overs of 1 to 16 cells did about as well), for about 90 and
  // 240 more load cycles.
  std::size_t firstBatchCells = 4;
  bool paced = true;
  std::string fpgaReport = bpaccel::fpgaReportPath(BPACCEL_M, BPACCEL_ARCH, BPACCEL_KEY_WIDTH);
  auto* benchCmd = app.add_subcommand(
      "bench", "Bouncing-cube benchmark: Bullet's, FCL's, CGAL's and ODE's broad phases against the accelerator");
  auto addSceneOptions = [](CLI::App* cmd, bpaccel::SceneConfig& sc) {
    cmd->add_option("--seed", sc.seed, "Scene seed")->capture_default_str();
    cmd->add_option("--density", sc.density, "Objects per unit volume (sets the cube's edge)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_option("--min-size", sc.minSize, "Smallest object size")->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_option("--max-size", sc.maxSize, "Largest object size")->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_option("--max-speed", sc.maxSpeed, "Largest initial speed per axis")->capture_default_str();
  };
  benchCmd->add_option("--objects", bench.objectCounts, "Object counts, one table row each")->capture_default_str()
      ->check(CLI::PositiveNumber);
  benchCmd->add_option("--cell-sizes", benchCells, "k-d tree cell sizes ('none' = no tree)")->capture_default_str();
  benchCmd->add_option("--grid-cell-sizes", lineUp.gridCellSizes,
                       "Cell sizes of the extra 'accelerator grid C' and 'cpu grid C' rows (uniform grid partition)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  benchCmd->add_option("--backend", benchBackend, "Where device cycles come from: rtl (Verilated) or model")
      ->check(CLI::IsMember({"rtl", "model"}))->capture_default_str();
  benchCmd->add_option("--frames", bench.frames, "Timed frames per row")->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_option("--warmup", bench.warmup, "Untimed frames before them")->capture_default_str();
  benchCmd->add_option("--clock-mhz", clockMHz, "Accelerator clock, MHz (default: measured Fmax, else 100 MHz)");
  benchCmd->add_option("--fpga-report", fpgaReport, "FPGA flow report whose Fmax is the default clock")
      ->capture_default_str();
  benchCmd->add_option("--link-gbytes-per-s", linkGBytesPerSecond,
                       "Modelled link bandwidth in gigabytes per second (1 GB/s = 1e9 bytes/s)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_option("--link-latency-us", linkLatencyUs,
                       "Modelled latency per hand-over to the accelerator (a batch of cells), microseconds")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  benchCmd->add_option("--cells-per-batch", cellsPerBatch,
                       "Cells per hand-over to the accelerator (its batch front end); 1: each cell on its own")
      ->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_option("--first-batch-cells", firstBatchCells,
                       "Cells of a frame's first hand-over, each next one twice as many up to --cells-per-batch "
                       "(slow start: the device starts before a whole batch is packed)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_flag("--paced,!--no-paced", paced,
                     "Also time each accelerator frame as its host threads run it (polled asynchronous hand-overs) "
                     "against a device emulated for its modelled time (needs --cells-per-batch of at least 2)")
      ->capture_default_str();
  benchCmd->add_option("--whole-step-objects", bench.wholeStepObjects,
                       "Also time full stepSimulation calls with btDbvtBroadphase and bpaccel::Broadphase at this "
                       "object count (0: not)")
      ->capture_default_str();
  benchCmd->add_option("--cpu-threads", lineUp.cpuThreads,
                       "Threads of the extra 'cpu k-d C, T threads' rows (default: every hardware thread; 0 or 1: none)")
      ->capture_default_str();
  benchCmd->add_option("--max-all-pairs-tests", lineUp.maxAllPairsTests,
                       "Skip methods that test all pairs (btSimpleBroadphase, k-d none) where n(n-1)/2 exceeds this")
      ->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_option("--max-sweep-tests", lineUp.maxSweepTests,
                       "Skip sweeps that cannot be stopped midway (FCL SaP rebuilt each frame, ODE sweep and prune) where more pairs "
                       "than this overlap on x")
      ->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_option("--max-method-seconds", bench.maxMethodSeconds,
                       "Stop a method for the rest of a row when its set-up or one frame takes longer, seconds")
      ->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_option("--json", benchJson, "Where to write every figure")->capture_default_str();
  addSceneOptions(benchCmd, bench.scene);

  bpaccel::SceneConfig sceneConfig;
  std::size_t sceneFrames = 30;
  std::string sceneOut = "results/scene.json";
  auto* sceneCmd = app.add_subcommand("scene", "Simulate a scene and write its objects' poses as JSON for rendering");
  sceneCmd->add_option("--objects", sceneConfig.objects, "Objects")->capture_default_str()->check(CLI::PositiveNumber);
  sceneCmd->add_option("--frames", sceneFrames, "Frames to simulate first")->capture_default_str();
  sceneCmd->add_option("--out", sceneOut, "Output JSON")->capture_default_str();
  addSceneOptions(sceneCmd, sceneConfig);

  CLI11_PARSE(app, argc, argv);
  try {
    if (*benchCmd) {
      lineUp.device = makeDevice(benchBackend, clockMHz, fpgaReport, linkGBytesPerSecond, linkLatencyUs,
                                 cellsPerBatch, firstBatchCells, paced);
      return runBench(bench, lineUp, benchCells, benchJson);
    }
    if (*sceneCmd) return runScene(sceneConfig, sceneFrames, sceneOut);
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
