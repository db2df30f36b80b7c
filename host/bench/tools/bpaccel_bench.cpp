// bpaccel-bench: the bouncing-cube benchmark (Bullet, the peers, the
// accelerator and the cpu backend), and the scene it runs on, for rendering.
//
//   bpaccel-bench run [--objects N ...] [--json FILE] ...   (see --help)
//   bpaccel-bench worlds [--worlds W] [--world-sizes N ...] [--json FILE]   (many small worlds)
//   bpaccel-bench scene [--objects N] [--frames F] [--out FILE]
//   bpaccel-bench boxes [--family F] [--objects N] [--frame K] [--out FILE]

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
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
#include "scenes/scene.hpp"
#include "scenes/scene_families.hpp"
#include "core/box_file.hpp"
#include "bpaccel_params.h"
#include "broad_phase/broad_phase.hpp"
#include "device/rtl/rtl_backend.hpp"

namespace {

// The device the accelerator methods model: this program's Verilated
// configuration; its clock and link come from the profiles it runs on.
std::shared_ptr<bpaccel::DeviceConfig> makeDevice(const std::string& backend, std::size_t cellsPerBatch,
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
  device->cellsPerBatch = cellsPerBatch;
  device->firstBatchCells = firstBatchCells;
  device->paced = paced && cellsPerBatch > 1;  // one cell a hand-over has nothing to overlap
  device->hardware["batch_cells"] = BPACCEL_BATCH_CELLS;
  return device;
}

// The platforms named by --profiles, for this build's device.
struct ProfileOptions {
  std::vector<std::string> names = bpaccel::builtInProfileNames();
  std::string fpgaDir = "results/fpga";
  std::string lfe5uReport = bpaccel::fpgaReportPath(BPACCEL_M, BPACCEL_ARCH, BPACCEL_KEY_WIDTH);
  double clockMHz = 0;  // > 0: every profile's clock, assumed
  double linkGBytesPerSecond = 4, linkLatencyUs = 1;  // the custom profile's link
};

std::vector<bpaccel::DeviceProfile> makeProfiles(const ProfileOptions& o) {
  const bpaccel::ProfileInputs in{.device = {BPACCEL_M, BPACCEL_ARCH, BPACCEL_KEY_WIDTH},
                                  .fpgaDir = o.fpgaDir,
                                  .lfe5uReport = o.lfe5uReport};
  std::vector<bpaccel::DeviceProfile> profiles;
  for (const auto& name : o.names) {
    auto p = name == "custom" ? bpaccel::customLinkProfile(in, o.linkGBytesPerSecond * 1e9, o.linkLatencyUs * 1e-6)
                              : bpaccel::builtInProfile(name, in);
    if (o.clockMHz > 0)
      p.part.clockHz = {o.clockMHz * 1e6, bpaccel::Provenance::Assumed, fmt::format("assumed: --clock-mhz {}", o.clockMHz)};
    profiles.push_back(std::move(p));
  }
  return profiles;
}

// The results of `run`, written to `jsonPath` unless it is empty; none, with
// the failure on stderr, when an exact method's answer was wrong.
std::optional<nlohmann::json> validatedRun(const std::function<nlohmann::json()>& run, const std::string& jsonPath) {
  nlohmann::json results;
  try {
    results = run();
  } catch (const bpaccel::ValidationFailure& e) {
    fmt::print(stderr, "bench: VALIDATION FAILED: {}\n", e.what());
    return std::nullopt;
  }
  if (jsonPath.empty()) return results;
  const std::filesystem::path path(jsonPath);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << results.dump(2) << "\n";
  return results;
}

// Where the results went, for the run's last line.
std::string resultsWhere(const std::string& jsonPath) {
  return jsonPath.empty() ? "not written (no --json)" : jsonPath;
}

int runBench(const bpaccel::BenchConfig& config, bpaccel::LineUpConfig lineUp, const std::vector<std::string>& cells,
             const std::string& jsonPath) {
  lineUp.cellSizes.clear();
  for (const auto& c : cells) lineUp.cellSizes.push_back(bpaccel::parseCellSize(c));
  for (const auto& p : lineUp.profiles) fmt::print(stderr, "bench: profile {}\n", p.summary());
  bpaccel::Benchmark bench(config, bpaccel::standardLineUp(lineUp), bpaccel::describe(lineUp),
                           [](const std::string& line) { fmt::print(stderr, "bench: {}\n", line); });
  const auto results = validatedRun([&] { return bench.run(); }, jsonPath);
  if (!results) return 3;
  fmt::print("{}", bpaccel::Benchmark::table(*results));
  fmt::print("\nAll frames validated. Results: {}\n", resultsWhere(jsonPath));
  for (const auto& r : (*results)["rows"])
    for (const auto& m : r["methods"])
      if (m["missing_pairs"].is_number() && m["missing_pairs"].get<std::uint64_t>() > 0)
        fmt::print(stderr, "bench: FINDING: {} missed {} exact pairs at n = {} (marked in the table)\n",
                   m["name"].get<std::string>(), m["missing_pairs"].get<std::uint64_t>(),
                   r["objects"].get<std::size_t>());
  return 0;
}

int runWorlds(const bpaccel::BenchConfig& config, const std::string& jsonPath) {
  bpaccel::ManyWorldsBenchConfig worlds = config.manyWorlds;
  worlds.scene = config.scene;
  for (const auto& p : worlds.profiles) fmt::print(stderr, "bench: profile {}\n", p.summary());
  const auto results = validatedRun(
      [&] {
        return bpaccel::runManyWorldsBench(worlds, bpaccel::manyWorldsLineUp(worlds.device), [](const std::string& line) {
          fmt::print(stderr, "bench: {}\n", line);
        });
      },
      jsonPath);
  if (!results) return 3;
  fmt::print("{}\nEvery world of every frame validated. Results: {}\n", bpaccel::manyWorldsTable(*results),
             resultsWhere(jsonPath));
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

// One frame of a scene family in the box-file format of `bpaccel pairs --input`.
int runBoxes(bpaccel::SceneConfig config, const std::string& family, std::size_t frame, const std::string& out) {
  const auto source = bpaccel::makeFrameSource(bpaccel::parseSceneFamily(family), config);
  for (std::size_t f = 0; f < frame; ++f) source->step();
  std::vector<bpaccel::Aabb> boxes;
  source->aabbs(boxes);
  const std::filesystem::path path(out);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream file(path);
  file << fmt::format("# {} {} objects, frame {}, seed {}\n", family, boxes.size(), frame, config.seed);
  bpaccel::writeBoxes(file, boxes);
  if (!file) throw std::runtime_error("cannot write " + out);
  fmt::print(stderr, "boxes: wrote {} boxes of {} (frame {}) to {}\n", boxes.size(), family, frame, out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{fmt::format("The bouncing-cube benchmark, with this build's accelerator (m = {}, capacity = {})",
                           BPACCEL_M, BPACCEL_CAPACITY)};
  app.require_subcommand(1);

  bpaccel::BenchConfig bench;
  bench.wholeStepObjects = 8000;
  bench.wholeStepRays = 500;
  bench.manyWorlds.worlds = 4096;
  bpaccel::LineUpConfig lineUp;
  lineUp.cpuThreads = std::thread::hardware_concurrency();
  std::vector<std::string> benchCells = {"none", "16", "32", "64", "128", "256"};
  std::string benchBackend = "rtl", benchJson;  // `make bench` names results/bench.json
  ProfileOptions profileOptions;
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
  std::vector<std::string> families = {"cube"};
  benchCmd->add_option("--families", families,
                       "Scene families, each at every object count: cube (Bullet's bouncing cube), sizes, clusters, "
                       "flat, poles, layer")
      ->capture_default_str();
  bool accelerator = true;
  benchCmd->add_flag("--accelerator,!--no-accelerator", accelerator,
                     "Run the accelerator's rows (a Verilated or modelled device beside the software)")
      ->capture_default_str();
  // A positive integer or 'none', as parseCellSize reads it; refused at parse time, naming the option.
  const CLI::Validator positiveOrNone(
      [](std::string& text) -> std::string {
        try {
          bpaccel::parseCellSize(text);
          return "";
        } catch (const std::invalid_argument& e) {
          return e.what();
        }
      },
      "UINT|none");
  benchCmd->add_option("--cell-sizes", benchCells, "k-d tree cell sizes ('none' = no tree)")
      ->check(positiveOrNone)->capture_default_str();
  benchCmd->add_option("--grid-cell-sizes", lineUp.gridCellSizes,
                       "Cell sizes of the extra 'accelerator grid C' and 'cpu grid C' rows (uniform grid partition)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  benchCmd->add_option("--backend", benchBackend, "Where device cycles come from: rtl (Verilated) or model")
      ->check(CLI::IsMember({"rtl", "model"}))->capture_default_str();
  benchCmd->add_option("--frames", bench.frames, "Timed frames per row")->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_option("--warmup", bench.warmup, "Untimed frames before them")->capture_default_str();
  benchCmd->add_option("--profiles", profileOptions.names,
                       "Platforms the accelerator rows are modelled on, each row once per profile and named by it: "
                       "ecp5-5g (LFE5UM5G-85F speed 8, PCIe Gen2 x1), gen3x8 (a PCIe Gen3 x8-class card), custom "
                       "(the LFE5U-85F with --link-gbytes-per-s and --link-latency-us)")
      ->check(CLI::IsMember({"ecp5-5g", "gen3x8", "custom"}))->capture_default_str();
  benchCmd->add_option("--clock-mhz", profileOptions.clockMHz,
                       "Accelerator clock of every profile, MHz, labelled assumed (default: each profile's part's "
                       "measured Fmax, or its labelled stand-in)");
  benchCmd->add_option("--fpga-report", profileOptions.lfe5uReport,
                       "The LFE5U-85F report whose Fmax is the stand-in clock of parts without their own")
      ->capture_default_str();
  benchCmd->add_option("--fpga-dir", profileOptions.fpgaDir,
                       "Where the FPGA reports are (the LFE5UM5G-85F's: <design>-*um5g*.json)")
      ->capture_default_str();
  benchCmd->add_option("--link-gbytes-per-s", profileOptions.linkGBytesPerSecond,
                       "The custom profile's link bandwidth in gigabytes per second (1 GB/s = 1e9 bytes/s)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  benchCmd->add_option("--link-latency-us", profileOptions.linkLatencyUs,
                       "The custom profile's latency per hand-over to the accelerator (a batch of cells), microseconds")
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
  benchCmd->add_option("--whole-step-rays", bench.wholeStepRays,
                       "Broad-phase rayTests cast after each timed whole step, timed and every answer checked (0: none)")
      ->capture_default_str();
  std::vector<std::string> queryObjects = {"8000", "100000"};
  benchCmd->add_option("--query-objects", queryObjects,
                       "Also time broad-phase rayTest and aabbTest, btDbvtBroadphase against bpaccel::BulletDropIn, "
                       "at these object counts (none: not)")
      ->check(positiveOrNone)->capture_default_str();
  benchCmd->add_option("--query-count", bench.queries.perKind, "Queries of each kind (two ray lengths, boxes) a round of the query table")
      ->check(CLI::PositiveNumber)->capture_default_str();
  const auto addWorldsOptions = [](CLI::App* cmd, bpaccel::ManyWorldsBenchConfig& w) {
    cmd->add_option("--world-sizes", w.boxesPerWorld, "Boxes per world of the many-worlds table, one column each")
        ->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_option("--world-frames", w.frames, "Timed frames of the many-worlds table")
        ->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_option("--world-warmup", w.warmup, "Untimed frames before them")->capture_default_str();
  };
  benchCmd->add_option("--many-worlds", bench.manyWorlds.worlds,
                       "Also run the many-worlds table: this many independent worlds a frame, found by the cpu "
                       "backend through ManyWorlds, by btDbvtBroadphase and FCL's tree one per world, and by the "
                       "accelerator through ManyWorlds, modelled per profile (0: not)")
      ->capture_default_str();
  addWorldsOptions(benchCmd, bench.manyWorlds);
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
  benchCmd->add_option("--json", benchJson, "Where to write every figure (nowhere unless given)");
  addSceneOptions(benchCmd, bench.scene);

  bpaccel::SceneConfig sceneConfig;
  std::size_t sceneFrames = 30;
  std::string sceneOut = "results/scene.json";
  auto* sceneCmd = app.add_subcommand("scene", "Simulate a scene and write its objects' poses as JSON for rendering");
  sceneCmd->add_option("--objects", sceneConfig.objects, "Objects")->capture_default_str()->check(CLI::PositiveNumber);
  sceneCmd->add_option("--frames", sceneFrames, "Frames to simulate first")->capture_default_str();
  sceneCmd->add_option("--out", sceneOut, "Output JSON")->capture_default_str();
  addSceneOptions(sceneCmd, sceneConfig);

  bpaccel::SceneConfig boxesConfig;
  std::string boxesFamily = "cube", boxesOut = "boxes.txt";
  std::size_t boxesFrame = 0;
  auto* boxesCmd = app.add_subcommand("boxes", "Write one frame of a scene family as a box file (bpaccel pairs --input)");
  boxesCmd->add_option("--family", boxesFamily, "cube, sizes, clusters, flat, poles or layer")->capture_default_str();
  boxesCmd->add_option("--objects", boxesConfig.objects, "Objects")->capture_default_str()->check(CLI::PositiveNumber);
  boxesCmd->add_option("--frame", boxesFrame, "Frames to move the scene first")->capture_default_str();
  boxesCmd->add_option("--out", boxesOut, "Output box file")->capture_default_str();
  addSceneOptions(boxesCmd, boxesConfig);

  bpaccel::BenchConfig worlds;
  worlds.manyWorlds.worlds = 4096;
  worlds.manyWorlds.frames = 20;
  worlds.manyWorlds.warmup = 2;
  std::string worldsBackend = "rtl", worldsJson;
  bool worldsAccelerator = true;
  auto* worldsCmd = app.add_subcommand(
      "worlds", "The many-worlds table alone: W small worlds a frame, every world's pairs validated");
  worldsCmd->add_option("--worlds", worlds.manyWorlds.worlds, "Worlds a frame")->check(CLI::PositiveNumber)
      ->capture_default_str();
  addWorldsOptions(worldsCmd, worlds.manyWorlds);
  worldsCmd->add_flag("--accelerator,!--no-accelerator", worldsAccelerator, "Run the accelerator's rows")
      ->capture_default_str();
  worldsCmd->add_option("--backend", worldsBackend, "Where device cycles come from: rtl (Verilated) or model")
      ->check(CLI::IsMember({"rtl", "model"}))->capture_default_str();
  worldsCmd->add_option("--profiles", profileOptions.names, "Platforms the accelerator rows are modelled on (as run's)")
      ->check(CLI::IsMember({"ecp5-5g", "gen3x8", "custom"}))->capture_default_str();
  worldsCmd->add_option("--json", worldsJson, "Where to write every figure (nowhere unless given)");
  addSceneOptions(worldsCmd, worlds.scene);

  CLI11_PARSE(app, argc, argv);
  try {
    if (*benchCmd) {
      bench.families.clear();
      for (const auto& f : families) bench.families.push_back(bpaccel::parseSceneFamily(f));
      if (accelerator) {
        lineUp.device = makeDevice(benchBackend, cellsPerBatch, firstBatchCells, paced);
        lineUp.profiles = makeProfiles(profileOptions);
        bench.manyWorlds.device = lineUp.device;
        bench.manyWorlds.profiles = lineUp.profiles;
      }
      bench.queries.objectCounts.clear();
      for (const auto& n : queryObjects)
        if (const auto count = bpaccel::parseCellSize(n)) bench.queries.objectCounts.push_back(*count);
      return runBench(bench, lineUp, benchCells, benchJson);
    }
    if (*worldsCmd) {
      if (worldsAccelerator) {
        worlds.manyWorlds.device = makeDevice(worldsBackend, cellsPerBatch, firstBatchCells, false);
        worlds.manyWorlds.profiles = makeProfiles(profileOptions);
      }
      return runWorlds(worlds, worldsJson);
    }
    if (*boxesCmd) return runBoxes(boxesConfig, boxesFamily, boxesFrame, boxesOut);
    return runScene(sceneConfig, sceneFrames, sceneOut);
  } catch (const std::exception& e) {
    fmt::print(stderr, "bpaccel-bench: {}\n", e.what());
    return 1;
  }
}
