// bpaccel-bench: the bouncing-cube benchmark (Bullet, the peers, the
// accelerator and the cpu backend), and the scene it runs on, for rendering.
//
//   bpaccel-bench run [--objects N ...] [--json FILE] ...   (see --help)
//   bpaccel-bench scene [--objects N] [--frames F] [--out FILE]

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

#include "device/backend.hpp"
#include "benchmark.hpp"
#include "scene.hpp"
#include "bpaccel_params.h"
#include "broad_phase/broad_phase.hpp"
#include "device/rtl/rtl_backend.hpp"

namespace {

// The device the accelerator methods model: this program's Verilated configuration.
std::shared_ptr<bpaccel::DeviceConfig> makeDevice(const std::string& backend, double clockMHz,
                                                  const std::string& fpgaReport, double linkGBytesPerSecond,
                                                  double linkLatencyUs, std::size_t cellsPerBatch,
                                                  std::size_t firstBatchCells, bool paced) {
  auto device = std::make_shared<bpaccel::DeviceConfig>();
  device->backend = backend;
  device->makeBackend = [backend] { return bpaccel::makeBuiltBackend(backend); };
  const bpaccel::DeviceParams built = bpaccel::builtDeviceParams();
  device->link.bytesPerBeat = static_cast<double>(built.resultBeatBytes());
  device->link.bytesPerBox = static_cast<double>(built.loadBoxBytes());
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
  device->link.latencySeconds = linkLatencyUs * 1e-6;
  device->cellsPerBatch = cellsPerBatch;
  device->firstBatchCells = firstBatchCells;
  device->paced = paced && cellsPerBatch > 1;  // one cell a hand-over has nothing to overlap
  device->hardware["batch_cells"] = BPACCEL_BATCH_CELLS;
  return device;
}

int runBench(const bpaccel::BenchConfig& config, bpaccel::LineUpConfig lineUp, const std::vector<std::string>& cells,
             const std::string& jsonPath) {
  lineUp.cellSizes.clear();
  for (const auto& c : cells) lineUp.cellSizes.push_back(bpaccel::parseCellSize(c));
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
  CLI::App app{fmt::format("The bouncing-cube benchmark, with this build's accelerator (m = {}, capacity = {})",
                           BPACCEL_M, BPACCEL_CAPACITY)};
  app.require_subcommand(1);

  bpaccel::BenchConfig bench;
  bench.wholeStepObjects = 8000;
  bench.queries.objectCounts = {8000, 100000};
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
      "run", "Bouncing-cube benchmark: Bullet's, FCL's, CGAL's and ODE's broad phases against the accelerator");
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
                       "Also time full stepSimulation calls with btDbvtBroadphase and bpaccel::BulletDropIn at this "
                       "object count (0: not)")
      ->capture_default_str();
  benchCmd->add_option("--query-objects", bench.queries.objectCounts,
                       "Also time broad-phase rayTest and aabbTest, btDbvtBroadphase against bpaccel::BulletDropIn, "
                       "at these object counts (none: not)")
      ->capture_default_str();
  benchCmd->add_option("--query-count", bench.queries.perKind, "Queries of each kind (two ray lengths, boxes) a round of the query table")
      ->check(CLI::PositiveNumber)->capture_default_str();
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
    return runScene(sceneConfig, sceneFrames, sceneOut);
  } catch (const std::exception& e) {
    fmt::print(stderr, "bpaccel-bench: {}\n", e.what());
    return 1;
  }
}
