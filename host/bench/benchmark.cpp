#include "benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <thread>

#include <fmt/format.h>

#include "device/cpu_backend.hpp"
#include "peers/bullet_methods.hpp"
#include "bullet/bullet_drop_in.hpp"
#include "core/median.hpp"
#include "scenes/step_timing.hpp"

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include "scenes/exact_pairs.hpp"
#include "peers/cgal/cgal_box_intersection.hpp"
#include "peers/fcl_managers.hpp"
#include "peers/ode_spaces.hpp"

namespace bpaccel {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string machineDescription() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

// One method of one row: its spec, the built method (or why it was skipped) and its samples.
struct Entry {
  const MethodSpec* spec = nullptr;
  std::unique_ptr<TimedMethod> method;
  std::optional<std::string> skipped;
  double setupSeconds = 0, updateSeconds = 0;
  std::vector<double> frameSeconds, hostSeconds, partitionSeconds, deviceSeconds, transferSeconds;
  std::vector<double> deviceCycles, loadCycles, cycles, runs, batches, boxesSent;
  std::vector<double> pipelinedSeconds;           // modelled overlap of the same frames
  std::vector<double> pacedSeconds;               // measured: the same frames' paced runs (TimedMethod::runPaced)
  std::shared_ptr<const FrameTimeline> timeline;  // the last timed frame's, for the plot
  double timelineSerialSeconds = 0;
  std::uint64_t missing = 0, extra = 0;  // against the exact set, over every frame (warm-up included)
  std::uint64_t duplicates = 0;          // pairs reported more than once
};

bool isBaseline(MethodKind k) { return k == MethodKind::Bullet || k == MethodKind::Peer; }

// Each "X, T threads" row of the cpu backend beside its one-thread row "X":
// the speedup of T threads over one, and that divided by T (1 = every core fully used).
void addParallelEfficiency(nlohmann::json& methods) {
  for (auto& m : methods) {
    const std::string name = m["name"];
    const auto comma = name.rfind(", ");
    if (m["kind"] != "cpu" || comma == std::string::npos || !name.ends_with(" threads") || !m["frame_ms"].is_object())
      continue;
    const std::size_t threads = std::stoul(name.substr(comma + 2));
    for (const auto& one : methods)
      if (one["name"] == name.substr(0, comma) && one["frame_ms"].is_object()) {
        const double speedup = one["frame_ms"]["median"].get<double>() / m["frame_ms"]["median"].get<double>();
        m["threads"] = threads;
        m["speedup_over_one_thread"] = speedup;
        m["parallel_efficiency"] = speedup / static_cast<double>(threads);
      }
  }
}

}  // namespace

// first_tenth and last_tenth: the medians of the first and of the last
// tenth of the frames, in order (at least one frame each), so a method that
// slows down or speeds up over a run shows it beside its median.
nlohmann::json summary(const std::vector<double>& v, double scale) {
  if (v.empty()) return nullptr;
  const auto tenth = static_cast<std::ptrdiff_t>(std::max<std::size_t>(1, v.size() / 10));
  return {{"median", median(v) * scale},
          {"min", *std::min_element(v.begin(), v.end()) * scale},
          {"max", *std::max_element(v.begin(), v.end()) * scale},
          {"first_tenth", median(std::vector<double>(v.begin(), v.begin() + tenth)) * scale},
          {"last_tenth", median(std::vector<double>(v.end() - tenth, v.end())) * scale}};
}

ValidationFailure::ValidationFailure(std::string method, std::size_t objects, std::size_t frame, SetDifference d,
                                     std::size_t exactPairs)
    : std::runtime_error(fmt::format("n={} frame {}: {} gave {} missing and {} extra pairs against the exact set of {}",
                                     objects, frame, method, d.missing, d.extra, exactPairs)),
      method_(std::move(method)),
      difference_(d) {}

SetDifference compareSorted(const std::vector<Pair>& got, const std::vector<Pair>& exact) {
  SetDifference d;
  std::size_t g = 0, e = 0;
  while (g < got.size() || e < exact.size()) {
    if (e == exact.size() || (g < got.size() && got[g] < exact[e])) {
      ++d.extra;
      ++g;
    } else if (g == got.size() || exact[e] < got[g]) {
      ++d.missing;
      ++e;
    } else {
      ++g;
      ++e;
    }
  }
  return d;
}

std::vector<MethodSpec> standardLineUp(const LineUpConfig& config) {
  std::vector<MethodSpec> specs = bulletMethods(config.maxAllPairsTests);
  for (auto&& group : {fclMethods(config.maxSweepTests), cgalMethods(), odeMethods(config.maxSweepTests)})
    for (auto& s : group) specs.push_back(s);
  const std::vector<std::optional<std::size_t>> gridCells(config.gridCellSizes.begin(), config.gridCellSizes.end());
  std::vector<std::shared_ptr<const DeviceConfig>> devices;
  if (config.device && config.profiles.empty()) devices.push_back(config.device);
  for (const auto& p : config.profiles)
    if (config.device) devices.push_back(std::make_shared<const DeviceConfig>(withProfile(*config.device, p)));
  for (const auto& device : devices) {
    for (auto& s : acceleratorMethods(device, config.cellSizes, config.maxAllPairsTests)) specs.push_back(std::move(s));
    for (auto& s : acceleratorMethods(device, gridCells, config.maxAllPairsTests, PartitionKind::UniformGrid))
      specs.push_back(std::move(s));
  }
  // The binning device (its C++ model) under each profile: the host sends each box once.
  if (config.device)
    for (auto& s : binningMethods(builtBinningParams(), config.profiles)) specs.push_back(std::move(s));
  for (auto& s : cpuMethods(config.cellSizes, config.maxAllPairsTests)) specs.push_back(std::move(s));
  for (auto& s : cpuMethods(gridCells, config.maxAllPairsTests, PartitionKind::UniformGrid))
    specs.push_back(std::move(s));
  if (config.cpuThreads > 1)
    for (auto& s : threadedCpuMethods(config.cellSizes, config.cpuThreads)) specs.push_back(std::move(s));
  for (auto& s : automaticCpuMethods(config.cpuThreads)) specs.push_back(std::move(s));
  specs.push_back(bpaccelFclMethod());
  return specs;
}

nlohmann::json describe(const LineUpConfig& config) {
  nlohmann::json cells = nlohmann::json::array();
  for (const auto& c : config.cellSizes) cells.push_back(cellSizeName(c));
  nlohmann::json j = {{"cell_sizes", cells}, {"grid_cell_sizes", config.gridCellSizes}, {"max_all_pairs_tests_per_frame", config.maxAllPairsTests},
                      {"max_sweep_tests", config.maxSweepTests}};
  if (const auto& d = config.device) {
    j["accelerator_backend"] = d->backend;
    j["hardware"] = d->hardware;
    j["link_model"] = {{"cells_per_batch", d->cellsPerBatch},
                       {"first_batch_cells", d->firstBatchCells ? std::min(d->firstBatchCells, d->cellsPerBatch)
                                                                : d->cellsPerBatch},
                       {"bytes_per_box", d->link.bytesPerBox},
                       {"bytes_per_result_beat", d->link.bytesPerBeat},
                       {"formula", "transfer = batches * latency + max(0, box bytes / bandwidth - load cycles / clock) "
                                   "+ result bytes / bandwidth; device = (load + compute + drain cycles) / clock"}};
    if (config.profiles.empty()) {
      // One platform, the device's own: its clock and link at the top, as they are not a profile's.
      j["clock_hz"] = d->clockHz;
      j["clock_source"] = d->clockSource;
      j["link_model"]["bandwidth_bytes_per_second"] = d->link.bandwidthBytesPerSecond;
      j["link_model"]["latency_seconds_per_run"] = d->link.latencySeconds;
    }
    j["profiles"] = nlohmann::json::array();
    for (const auto& p : config.profiles) j["profiles"].push_back(p.toJson());
  }
  return j;
}

Benchmark::Benchmark(BenchConfig config, std::vector<MethodSpec> lineUp, nlohmann::json configuration,
                     Progress progress)
    : config_(std::move(config)),
      lineUp_(std::move(lineUp)),
      configuration_(std::move(configuration)),
      progress_(std::move(progress)) {
  if (config_.frames == 0) throw std::invalid_argument("bench: at least one timed frame");
  for (const auto& s : lineUp_)
    if (s.name.empty() || !s.make) throw std::invalid_argument("bench: every method needs a name and a factory");
}

nlohmann::json Benchmark::run() {
  nlohmann::json out;
  out["configuration"] = configuration_;
  out["configuration"].update({
      {"object_counts", config_.objectCounts},
      {"frames", config_.frames},
      {"warmup_frames", config_.warmup},
      {"method_order", "shuffled every frame (seeded by the scene seed and the frame)"},
      {"scene",
       {{"min_size", config_.scene.minSize},
        {"max_size", config_.scene.maxSize},
        {"density_objects_per_unit3", config_.scene.density},
        {"max_speed", config_.scene.maxSpeed},
        {"max_spin", config_.scene.maxSpin},
        {"time_step", config_.scene.timeStep},
        {"seed", config_.scene.seed}}},
  });
  out["machine"] = {{"cpu", machineDescription()},
                    {"hardware_threads", std::thread::hardware_concurrency()},
                    {"compiler", __VERSION__},
                    {"libraries",
                     {"Bullet 3.24", "FCL 0.7.0", "CGAL 5.5.1", "ODE 0.16.2 (double precision)"}}};
  out["notes"] = {
      {"measured", "Bullet and peer broad phases, cpu backend, accelerator host part (float-to-key conversion, "
                   "partition (k-d tree or grid), packing, remapping and filtering pairs)"},
      {"modelled", "accelerator device part (device cycles, loads included, / clock) and transfer part (link model)"},
      {"threads", "every method runs on one thread, but the rows 'cpu k-d C, T threads' (the cpu backend's cells "
                  "shared out among T threads)"}};
  out["configuration"]["families"] = nlohmann::json::object();
  for (SceneFamily f : config_.families)
    out["configuration"]["families"][std::string(familyName(f))] = familyDescription(f);
  out["rows"] = nlohmann::json::array();
  for (SceneFamily f : config_.families)
    for (std::size_t n : config_.objectCounts) out["rows"].push_back(runRow(f, n));
  if (config_.wholeStepObjects) out["whole_step"] = wholeSteps();
  if (!config_.queries.objectCounts.empty()) {
    QueryBenchConfig queries = config_.queries;
    queries.scene = config_.scene;
    out["queries"] = runQueryBench(queries, progress_);
  }
  if (config_.manyWorlds.worlds) {
    ManyWorldsBenchConfig worlds = config_.manyWorlds;
    worlds.scene = config_.scene;
    out["many_worlds"] = runManyWorldsBench(worlds, manyWorldsLineUp(worlds.device), progress_);
  }
  out["validation"] = "every frame of every method compared with the exact set: accelerator and cpu equal to it (a "
                      "difference stops the run); Bullet and peers counted (extra allowed, missing reported)";
  return out;
}

namespace {

// The last timed frame of the accelerator method whose modelled pipelined
// frame is the fastest of the row: its lanes in ms, for the timeline plot.
nlohmann::json timelineJson(const std::vector<Entry>& entries, std::size_t objects) {
  const Entry* best = nullptr;
  for (const Entry& e : entries)
    if (e.timeline && (!best || median(e.pipelinedSeconds) < median(best->pipelinedSeconds))) best = &e;
  if (!best) return nullptr;
  const FrameTimeline& t = *best->timeline;
  const auto lane = [](const std::vector<Span>& spans) {
    nlohmann::json a = nlohmann::json::array();
    for (const Span& s : spans) a.push_back({s.start * 1e3, s.end * 1e3});
    return a;
  };
  return {{"method", best->spec->name},
          {"objects", objects},
          {"batches", t.device.size()},
          {"frame_ms", t.frameSeconds * 1e3},
          {"serial_ms", best->timelineSerialSeconds * 1e3},
          {"paced_ms", best->pacedSeconds.empty() ? nlohmann::json(nullptr)
                                                  : nlohmann::json(median(best->pacedSeconds) * 1e3)},
          {"what", fmt::format("one frame: host work measured (produce = keys, partition, packing; decode = "
                               "decoding and filtering), scheduled as the polled asynchronous hand-overs run it (one "
                               "host thread produces and decodes, at most {} batches out) by the model; link and "
                               "device modelled. paced_ms: the same method's paced runs, median, measured",
                               kBatchesInFlight)},
          {"lanes", {{"produce", lane(t.produce)}, {"link", lane(t.link)}, {"device", lane(t.device)},
                     {"decode", lane(t.decode)}}}};
}

}  // namespace

// A simulation's whole step, not just its broad phase: what a user of the
// world would see, with a game's broad-phase ray tests after each step. Each
// world starts from the same seed; both are measured.
nlohmann::json Benchmark::wholeSteps() {
  SceneConfig sc = config_.scene;
  sc.objects = config_.wholeStepObjects;
  const WholeStepConfig steps{.frames = config_.wholeStepFrames, .warmup = 3, .rays = config_.wholeStepRays};
  constexpr std::size_t kCell = 64;
  struct Candidate {
    std::string name;
    BtBroadphaseFactory make;
    bool exact;  // its rays must report exactly the proxies Bullet's ray-box test accepts
  };
  const std::vector<Candidate> candidates = {
      {"btDbvtBroadphase", [] { return std::make_unique<btDbvtBroadphase>(); }, false},
      {fmt::format("bpaccel::BulletDropIn, cpu backend, k-d {}", kCell),
       [] { return std::make_unique<BulletDropIn>(std::make_unique<CpuBackend>(), BulletDropInOptions{kCell}); },
       true}};
  nlohmann::json methods = nlohmann::json::array();
  for (const auto& c : candidates) {
    progress_(fmt::format("whole step, n={}: {}", sc.objects, c.name));
    const StepTimes t = timeWholeSteps(sc, c.make, steps);
    nlohmann::json m = {{"name", c.name}, {"step_ms", summary(t.stepSeconds, 1e3)}};
    if (steps.rays) {
      if (c.exact && (t.rayMissing || t.rayExtra))
        throw std::runtime_error(fmt::format("whole step: {}'s ray tests gave {} missing and {} extra proxies", c.name,
                                             t.rayMissing, t.rayExtra));
      std::vector<double> frame(t.stepSeconds.size());
      for (std::size_t f = 0; f < frame.size(); ++f) frame[f] = t.stepSeconds[f] + t.raySeconds[f];
      m["rays_ms"] = summary(t.raySeconds, 1e3);
      m["step_and_rays_ms"] = summary(frame, 1e3);
      m["ray_proxies"] = {{"reported", t.rayHits}, {"extra", t.rayExtra}, {"missing", t.rayMissing}};
    }
    methods.push_back(m);
  }
  return {{"objects", sc.objects},
          {"frames", steps.frames},
          {"warmup_frames", steps.warmup},
          {"rays_per_frame", steps.rays},
          {"what", "measured: full btDiscreteDynamicsWorld::stepSimulation (broad phase, pair cache updates, narrow "
                   "phase, solver) of the bouncing cube, one world per broad phase from the same seed; then "
                   "rays_per_frame broad-phase rayTests (random segments in the cube, 1 to an edge long), each "
                   "ray's proxies checked against Bullet's ray-box test on every proxy's box (extra: btDbvtBroadphase's "
                   "padded leaves)"},
          {"methods", methods}};
}

nlohmann::json Benchmark::runRow(SceneFamily family, std::size_t objects) {
  SceneConfig sc = config_.scene;
  sc.objects = objects;
  const auto tScene = Clock::now();
  const std::unique_ptr<FrameSource> source = makeFrameSource(family, sc);
  FrameSource& scene = *source;
  std::vector<Aabb> boxes;
  scene.aabbs(boxes);
  const double sceneSetup = since(tScene);
  const auto worldLo = scene.worldLo(), worldHi = scene.worldHi();
  const SceneStart start{boxes, *std::min_element(worldLo.begin(), worldLo.end()),
                         *std::max_element(worldHi.begin(), worldHi.end()), worldLo, worldHi};
  // Failures name the family (but the cube's, the benchmark's first scene).
  const std::string familyPrefix = family == SceneFamily::Cube ? "" : fmt::format("{}: ", familyName(family));
  const auto rowName = [&] {
    return family == SceneFamily::Cube ? fmt::format("n={}", objects)
                                       : fmt::format("{} n={}", familyName(family), objects);
  };

  std::vector<Entry> entries(lineUp_.size());
  std::vector<std::size_t> active;
  for (std::size_t k = 0; k < lineUp_.size(); ++k) {
    Entry& e = entries[k];
    e.spec = &lineUp_[k];
    if (e.spec->skipReason) e.skipped = e.spec->skipReason(start);
    if (e.skipped) {
      progress_(fmt::format("{} {}: skipped: {}", rowName(), e.spec->name, *e.skipped));
      continue;
    }
    progress_(fmt::format("{} {}: set-up", rowName(), e.spec->name));
    const auto t0 = Clock::now();
    e.method = e.spec->make(start);
    e.setupSeconds = since(t0);
    if (e.setupSeconds > config_.maxMethodSeconds) {
      e.skipped = fmt::format("its set-up took {:.0f} s, above the limit of {:.0f} s (--max-method-seconds)",
                              e.setupSeconds, config_.maxMethodSeconds);
      e.method.reset();
      progress_(fmt::format("{} {}: stopped: {}", rowName(), e.spec->name, *e.skipped));
      continue;
    }
    active.push_back(k);
  }

  std::vector<Pair> exact, got;
  std::uint64_t exactTotal = 0;
  double physicsSeconds = 0, exactSeconds = 0, validationSeconds = 0;
  const std::size_t totalFrames = config_.warmup + config_.frames;
  const std::optional<double> energyStart = scene.kineticEnergy();
  std::mt19937 shuffler(sc.seed);
  std::vector<std::size_t> order = active;
  // The method's last pairs against this frame's exact set, and how many it
  // reported more than once (FCL's spatial hash, once per shared cell),
  // counted apart from extra pairs.
  struct Checked {
    SetDifference difference;
    std::uint64_t duplicates = 0;
  };
  const auto checkPairs = [&](TimedMethod& method) {
    const auto tv = Clock::now();
    method.pairs(got);
    std::sort(got.begin(), got.end());
    const auto unique = std::unique(got.begin(), got.end());
    Checked c;
    c.duplicates = static_cast<std::uint64_t>(got.end() - unique);
    got.erase(unique, got.end());
    c.difference = compareSorted(got, exact);
    validationSeconds += since(tv);
    return c;
  };
  // A method's paced run (TimedMethod::runPaced) of this frame's boxes,
  // timed and validated like an update.
  const auto timePaced = [&](Entry& e, std::size_t frame) {
    e.method->readyPacedDevice();
    const auto t0 = Clock::now();
    e.method->runPaced(boxes);
    const double wall = since(t0);
    const auto [d, duplicates] = checkPairs(*e.method);
    if (d.missing || d.extra || duplicates)
      throw ValidationFailure(familyPrefix + e.spec->name + " (paced run)", objects, frame, d, exact.size());
    return wall;
  };
  for (std::size_t frame = 0; frame < totalFrames; ++frame) {
    const bool timed = frame >= config_.warmup;
    progress_(fmt::format("{} frame {}/{}{}", rowName(), frame + 1, totalFrames, timed ? "" : " (warm-up)"));
    auto t = Clock::now();
    scene.step();
    scene.aabbs(boxes);
    physicsSeconds += since(t);
    t = Clock::now();
    exactPairs(boxes, exact);
    exactSeconds += since(t);
    if (timed) exactTotal += exact.size();
    // A new order every frame: no method always follows the one that empties the caches.
    std::erase_if(order, [&](std::size_t k) { return entries[k].skipped.has_value(); });
    std::shuffle(order.begin(), order.end(), shuffler);
    for (std::size_t k : order) {
      Entry& e = entries[k];
      const auto t0 = Clock::now();
      e.method->update(boxes);
      const double wall = since(t0);
      e.updateSeconds += wall;
      const FrameTime ft = e.method->frameTime(wall);
      const auto [d, duplicates] = checkPairs(*e.method);
      e.missing += d.missing;
      e.extra += d.extra;
      e.duplicates += duplicates;
      if (mustBeExact(e.spec->kind) && (d.missing || d.extra || duplicates))
        throw ValidationFailure(familyPrefix + e.spec->name, objects, frame, d, exact.size());
      if (wall > config_.maxMethodSeconds) {
        e.skipped = fmt::format("stopped at frame {}: one update took {:.0f} s, above the limit of {:.0f} s "
                                "(--max-method-seconds); that frame was validated",
                                frame + 1, wall, config_.maxMethodSeconds);
        progress_(fmt::format("{} {}: {}", rowName(), e.spec->name, *e.skipped));
        continue;
      }
      if (!timed) continue;
      e.frameSeconds.push_back(ft.seconds);
      if (const auto& p = ft.parts) {
        e.hostSeconds.push_back(p->hostSeconds);
        e.partitionSeconds.push_back(p->partitionSeconds);
        e.deviceSeconds.push_back(p->deviceSeconds);
        e.transferSeconds.push_back(p->transferSeconds);
        e.deviceCycles.push_back(static_cast<double>(p->stats.deviceCycles()));
        e.loadCycles.push_back(static_cast<double>(p->stats.loadCycles));
        e.cycles.push_back(static_cast<double>(p->stats.cycles));
        e.runs.push_back(static_cast<double>(p->stats.runs));
        e.batches.push_back(static_cast<double>(p->stats.batches));
        e.boxesSent.push_back(static_cast<double>(p->stats.boxesSent));
        if (p->pipeline) {
          e.pipelinedSeconds.push_back(p->pipeline->frameSeconds);
          e.timeline = p->pipeline;
          e.timelineSerialSeconds = ft.seconds;
        }
      }
    }
    // The paced runs after every update of the frame, in an order of their
    // own: each follows other methods' work, as each update does, not its
    // own update on the same boxes.
    std::vector<std::size_t> pacedOrder;
    for (std::size_t k : order)
      if (!entries[k].skipped && entries[k].method->hasPacedRun()) pacedOrder.push_back(k);
    std::shuffle(pacedOrder.begin(), pacedOrder.end(), shuffler);
    for (std::size_t k : pacedOrder) {
      const double wall = timePaced(entries[k], frame);
      if (timed) entries[k].pacedSeconds.push_back(wall);
    }
  }

  nlohmann::json teardown = nlohmann::json::object();
  for (Entry& e : entries)
    if (e.method) {
      const auto t0 = Clock::now();
      e.method.reset();
      teardown[e.spec->name] = since(t0);
    }
  for (Entry& e : entries)
    if (e.skipped) e.frameSeconds.clear();  // a stopped method's frames are not reported

  nlohmann::json row;
  row["objects"] = objects;
  row["family"] = familyName(family);
  row["world"] = {{"lo", worldLo}, {"hi", worldHi}};
  if (const auto edge = scene.cubeEdge()) row["cube_edge"] = *edge;
  row["exact_pairs_per_frame_mean"] = static_cast<double>(exactTotal) / static_cast<double>(config_.frames);
  if (energyStart) row["kinetic_energy_start_end"] = {*energyStart, *scene.kineticEnergy()};

  // The baselines a user would pick instead: the fastest of all that found
  // every pair, and the fastest of each library.
  const Entry* fastest = nullptr;
  std::map<std::string, const Entry*> fastestOf;
  for (const Entry& e : entries) {
    if (e.skipped || !isBaseline(e.spec->kind)) continue;
    const double t = median(e.frameSeconds);
    const Entry*& lib = fastestOf[e.spec->library];
    if (!lib || t < median(lib->frameSeconds)) lib = &e;
    if (e.missing == 0 && (!fastest || t < median(fastest->frameSeconds))) fastest = &e;
  }
  const auto baselineJson = [](const Entry* e) -> nlohmann::json {
    if (!e) return nullptr;
    return {{"name", e->spec->name}, {"library", e->spec->library}, {"frame_ms", median(e->frameSeconds) * 1e3}};
  };
  row["fastest_baseline"] = baselineJson(fastest);
  row["fastest_per_library"] = nlohmann::json::object();
  for (const auto& [lib, e] : fastestOf) row["fastest_per_library"][lib] = baselineJson(e);
  if (fastestOf.count("Bullet 3.24")) row["fastest_bullet"] = fastestOf["Bullet 3.24"]->spec->name;

  nlohmann::json methods = nlohmann::json::array();
  for (const Entry& e : entries) {
    nlohmann::json j;
    j["name"] = e.spec->name;
    j["kind"] = kindName(e.spec->kind);
    j["library"] = e.spec->library;
    j["cell_size"] = e.spec->partition == partitionName(PartitionKind::Automatic) ? nlohmann::json("auto")
                     : e.spec->cellSize ? nlohmann::json(*e.spec->cellSize)
                                        : nlohmann::json("none");
    if (!e.spec->partition.empty()) j["partition"] = e.spec->partition;
    if (!e.spec->profile.is_null()) j["profile"] = e.spec->profile;
    if (e.skipped) {
      j["skipped"] = *e.skipped;
      j["frame_ms"] = nullptr;
      j["missing_pairs"] = nullptr;
      j["extra_pairs"] = nullptr;
      methods.push_back(j);
      continue;
    }
    j["frame_ms"] = summary(e.frameSeconds, 1e3);
    j["missing_pairs"] = e.missing;
    j["extra_pairs"] = e.extra;
    j["duplicate_pairs"] = e.duplicates;
    j["found_every_pair"] = e.missing == 0;
    j["setup_s"] = e.setupSeconds;
    j["update_s_total"] = e.updateSeconds;
    if (!e.hostSeconds.empty()) {
      j["host_ms_measured"] = summary(e.hostSeconds, 1e3);
      j["host_partition_ms_measured"] = summary(e.partitionSeconds, 1e3);
      j["device_ms_modelled"] = summary(e.deviceSeconds, 1e3);
      j["transfer_ms_modelled"] = summary(e.transferSeconds, 1e3);
      j["device_cycles"] = summary(e.deviceCycles, 1);
      j["load_cycles"] = summary(e.loadCycles, 1);
      j["cycles"] = summary(e.cycles, 1);
      j["runs"] = summary(e.runs, 1);
      j["batches"] = summary(e.batches, 1);
      j["boxes_sent"] = summary(e.boxesSent, 1);
      j["serial_frame_ms"] = summary(e.frameSeconds, 1e3);
      j["pipelined_frame_ms_modelled"] = summary(e.pipelinedSeconds, 1e3);
    }
    if (!e.pacedSeconds.empty()) {
      j["paced_frame_ms"] = summary(e.pacedSeconds, 1e3);
      j["paced_acceleration_over_fastest_baseline"] =
          fastest ? nlohmann::json(median(fastest->frameSeconds) / median(e.pacedSeconds)) : nullptr;
    }
    const double mine = median(e.frameSeconds);
    nlohmann::json acc = nlohmann::json::object();
    for (const Entry& b : entries)
      if (!b.skipped && isBaseline(b.spec->kind)) acc[b.spec->name] = median(b.frameSeconds) / mine;
    j["acceleration_over"] = acc;
    j["acceleration_over_fastest_baseline"] = fastest ? nlohmann::json(median(fastest->frameSeconds) / mine) : nullptr;
    methods.push_back(j);
  }
  addParallelEfficiency(methods);
  row["methods"] = methods;
  row["timeline"] = timelineJson(entries, objects);

  nlohmann::json setup = nlohmann::json::object(), update = nlohmann::json::object();
  for (const Entry& e : entries)
    if (!e.skipped) {
      setup[e.spec->name] = e.setupSeconds;
      update[e.spec->name] = e.updateSeconds;
    }
  row["time_s"] = {{"scene_setup", sceneSetup},       {"physics_steps", physicsSeconds},
                   {"exact_reference", exactSeconds}, {"validation", validationSeconds},
                   {"method_setup", setup},           {"method_updates", update},
                   {"method_teardown", teardown}};
  return row;
}

namespace {

std::string pad(const std::string& s, std::size_t w) { return s.size() >= w ? s + " " : s + std::string(w - s.size(), ' '); }

const nlohmann::json* findMethod(const nlohmann::json& row, const std::string& name) {
  for (const auto& m : row["methods"])
    if (m["name"] == name) return &m;
  return nullptr;
}

// The cpu backend's rows on several threads: speedup over one thread, and per thread.
std::string parallelTable(const nlohmann::json& rows, const std::vector<std::string>& names, std::size_t nameWidth) {
  std::string body;
  for (const auto& name : names) {
    std::string line;
    bool any = false;
    for (const auto& r : rows) {
      const auto* m = findMethod(r, name);
      any = any || (m && m->contains("parallel_efficiency"));
      line += m && m->contains("parallel_efficiency")
                  ? fmt::format("{:>16}", fmt::format("{:.2f}x {:.2f}", (*m)["speedup_over_one_thread"].get<double>(),
                                                      (*m)["parallel_efficiency"].get<double>()))
                  : fmt::format("{:>16}", "-");
    }
    if (any) body += pad(name, nameWidth) + line + "\n";
  }
  if (body.empty()) return body;
  std::string t = "\nParallel efficiency of the cpu backend: speedup of T threads over the same row on one thread, "
                  "and that speedup / T (measured in this run)\n" + pad("method", nameWidth);
  for (const auto& r : rows) t += fmt::format("{:>16}", fmt::format("n={}", r["objects"].get<std::size_t>()));
  return t + "\n" + body;
}

// The whole steps, and with rays the step plus its ray tests.
std::string wholeStepTable(const nlohmann::json& w) {
  const std::size_t rays = w.value("rays_per_frame", std::size_t{0});
  std::string t = fmt::format("\nWhole stepSimulation of the bouncing cube, n={}, median of {} frames, ms (measured; the "
                              "broad phase is only part of a step){}:\n",
                              w["objects"].get<std::size_t>(), w["frames"].get<std::size_t>(),
                              rays ? fmt::format("; then {} broad-phase ray tests, every answer checked", rays) : "");
  if (rays) t += fmt::format("  {} {:>12} {:>12} {:>14}\n", pad("", 44), "step", "rays", "step + rays");
  const auto first = w["methods"][0];
  const char* key = rays ? "step_and_rays_ms" : "step_ms";
  for (const auto& m : w["methods"]) {
    const double whole = m[key]["median"].get<double>();
    t += fmt::format("  {} {:>12.3f}", pad(m["name"], 44), m["step_ms"]["median"].get<double>());
    if (rays)
      t += fmt::format(" {:>12.3f} {:>14.3f}   (ray proxies: extra {}, missing {})", m["rays_ms"]["median"].get<double>(),
                       whole, m["ray_proxies"]["extra"].get<std::uint64_t>(),
                       m["ray_proxies"]["missing"].get<std::uint64_t>());
    t += fmt::format("   {:.2f}x\n", first[key]["median"].get<double>() / whole);
  }
  return t;
}

// Bullet's and the peers' first and last tenth of frames beside the median:
// a broad phase whose structure decays over a run shows it here.
std::string tenthsTable(const nlohmann::json& rows, const std::vector<std::string>& names, std::size_t nameWidth) {
  std::string t = "\nBullet and the peers over the run: median of the first tenth of the timed frames / median of "
                  "all / median of the last tenth, ms\n" + pad("method", nameWidth);
  for (const auto& r : rows) t += fmt::format("{:>28}", fmt::format("n={}", r["objects"].get<std::size_t>()));
  t += "\n";
  for (const auto& name : names) {
    std::string line;
    bool baseline = false;
    for (const auto& r : rows) {
      const auto* m = findMethod(r, name);
      baseline = baseline || (m && ((*m)["kind"] == "bullet" || (*m)["kind"] == "peer"));
      if (!m || m->contains("skipped") || !(*m)["frame_ms"].is_object()) {
        line += fmt::format("{:>28}", "-");
        continue;
      }
      const auto& f = (*m)["frame_ms"];
      line += fmt::format("{:>28}", fmt::format("{:.3f} / {:.3f} / {:.3f}", f["first_tenth"].get<double>(),
                                                f["median"].get<double>(), f["last_tenth"].get<double>()));
    }
    if (baseline) t += pad(name, nameWidth) + line + "\n";
  }
  return t;
}

}  // namespace

std::string Benchmark::table(const nlohmann::json& results) {
  std::string t;
  const auto& rows = results["rows"];
  if (rows.empty()) return t;
  // One table per scene family, each over that family's rows.
  std::vector<std::string> families;
  for (const auto& r : rows)
    if (const auto f = r.value("family", std::string("cube")); std::find(families.begin(), families.end(), f) == families.end())
      families.push_back(f);
  if (families.size() > 1) {
    for (const auto& f : families) {
      nlohmann::json part = results;
      part["rows"] = nlohmann::json::array();
      for (const auto& r : rows)
        if (r.value("family", std::string("cube")) == f) part["rows"].push_back(r);
      t += fmt::format("\n=== Scene family '{}': {} ===\n", f, familyDescription(parseSceneFamily(f)));
      t += table(part);
    }
    return t;
  }
  const auto& cfg = results["configuration"];
  constexpr std::size_t kName = 40;  // "bpaccel::BroadPhaseManager, cpu grid 64"
  std::vector<std::string> names;  // every method of any row, in line-up order
  for (const auto& r : rows)
    for (const auto& m : r["methods"])
      if (std::find(names.begin(), names.end(), m["name"].get<std::string>()) == names.end()) names.push_back(m["name"]);
  const auto header = [&](const std::string& title) {
    t += fmt::format("\n{}\n{}", title, pad("method", kName));
    for (const auto& r : rows) t += fmt::format("{:>16}", fmt::format("n={}", r["objects"].get<std::size_t>()));
    t += "\n";
  };
  const auto kindOf = [&](const std::string& name) {
    for (const auto& r : rows)
      if (const auto* m = findMethod(r, name)) return (*m)["kind"].get<std::string>();
    return std::string();
  };
  // One line per accelerator method: `cell` of its JSON entry in each row ("-" where it has none).
  const auto acceleratorRows = [&](const auto& cell) {
    for (const auto& name : names) {
      if (kindOf(name) != "accelerator") continue;
      t += pad(name, kName);
      for (const auto& r : rows) {
        const auto* m = findMethod(r, name);
        t += fmt::format("{:>16}", m ? cell(*m) : std::string("-"));
      }
      t += "\n";
    }
  };
  const auto isOurs = [&](const std::string& name) {
    const auto k = kindOf(name);
    return k == "accelerator" || k == "cpu";
  };

  std::string legend = "accelerator = measured host + modelled device + modelled transfer";
  if (cfg.contains("link_model")) {
    const auto perBatch = cfg["link_model"].value("cells_per_batch", std::size_t{1});
    const auto first = cfg["link_model"].value("first_batch_cells", perBatch);
    const std::string handOvers =
        first < perBatch ? fmt::format("hand-over; a frame's first holds {} cells, each next twice as many up to {}",
                                       first, perBatch)
                         : fmt::format("hand-over of up to {} cells", perBatch);
    // A device of narrower keys gets them narrowed per cell, its pairs checked on the host (docs/host.md).
    const auto keyWidth = cfg.contains("hardware") ? cfg["hardware"].value("key_width", 32) : 32;
    const std::string keys = keyWidth == 32 ? "" : fmt::format(", {}-bit keys narrowed per cell", keyWidth);
    // Each platform: the device's own clock and link, or each profile's, named.
    std::string platforms;
    if (cfg.contains("clock_hz"))
      platforms = fmt::format("{:.1f} MHz; link {:.1f} GB/s, {:.1f} us per {}", cfg["clock_hz"].get<double>() / 1e6,
                              cfg["link_model"]["bandwidth_bytes_per_second"].get<double>() / 1e9,
                              cfg["link_model"]["latency_seconds_per_run"].get<double>() * 1e6, handOvers);
    else
      platforms = "rows 'on P' modelled on profile P, latency per " + handOvers;
    for (const auto& p : cfg.value("profiles", nlohmann::json::array()))
      platforms += "; profile " + p["summary"].get<std::string>();
    legend = fmt::format(
        "accelerator = measured host + modelled device (device cycles with loads, {} backend{}) + modelled transfer "
        "({}; boxes stream through the {:g}-byte-a-cycle load port, so only the link's excess over one cycle a box "
        "counts; 'accelerator binning': the binning device's C++ cycle model, each box sent once, the link's excess over "
        "its intake, at the binning design's own clock where its report on the profile's part is valid, else the "
        "stream device's standing in (the profile says which))",
        cfg["accelerator_backend"].get<std::string>(), keys, platforms, cfg["link_model"].value("bytes_per_box", 24.0));
  }
  header("Median broad-phase time per frame, ms, one thread unless named (" + legend +
         "; ! = missed exact pairs; - = skipped, see below)");
  for (const auto& name : names) {
    t += pad(name, kName);
    for (const auto& r : rows) {
      const auto* m = findMethod(r, name);
      if (!m || m->contains("skipped"))
        t += fmt::format("{:>16}", "-");
      else
        t += fmt::format("{:>15.4f}{}", (*m)["frame_ms"]["median"].get<double>(),
                         (*m)["missing_pairs"].get<std::uint64_t>() ? "!" : " ");
    }
    t += "\n";
  }

  header(fmt::format("Accelerator frame with host, link and device overlapped, ms: MODELLED schedule of the "
                     "host's polled asynchronous hand-overs (one host thread produces and decodes, at most {} "
                     "batches out) applied to the same frames' measured host work of the serial runs above",
                     kBatchesInFlight));
  acceleratorRows([](const nlohmann::json& m) -> std::string {
    if (m.contains("skipped") || !m.contains("pipelined_frame_ms_modelled") ||
        m["pipelined_frame_ms_modelled"].is_null())
      return "-";
    return fmt::format("{:.4f}", m["pipelined_frame_ms_modelled"]["median"].get<double>());
  });

  bool anyPaced = false;
  for (const auto& r : rows)
    for (const auto& m : r["methods"]) anyPaced = anyPaced || m.contains("paced_frame_ms");
  if (anyPaced) {
    header("Accelerator frame as its host threads run it, ms, and its acceleration over the fastest above: MEASURED "
           "wall time of the polled asynchronous hand-overs (one host thread produces and decodes; the device on a "
           "thread of its own) against a device EMULATED for its modelled time (each frame's answers recorded in its "
           "serial run, replayed after the modelled load, run and link times), after every update of the frame");
    acceleratorRows([](const nlohmann::json& m) -> std::string {
      if (!m.contains("paced_frame_ms")) return "-";
      const double ms = m["paced_frame_ms"]["median"].get<double>();
      const auto& over = m["paced_acceleration_over_fastest_baseline"];
      return over.is_null() ? fmt::format("{:.4f}", ms) : fmt::format("{:.4f} ({:.1f}x)", ms, over.get<double>());
    });
  }

  const auto accelerationBlock = [&](const std::string& title, const auto& baselineOf) {
    header(title);
    t += "  over:";
    for (const auto& r : rows) {
      const nlohmann::json b = baselineOf(r);
      t += fmt::format(" n={} {};", r["objects"].get<std::size_t>(),
                       b.is_null() ? std::string("-")
                                   : fmt::format("{} ({:.4f} ms)", b["name"].get<std::string>(), b["frame_ms"].get<double>()));
    }
    t += "\n";
    for (const auto& name : names) {
      if (!isOurs(name)) continue;
      t += pad(name, kName);
      for (const auto& r : rows) {
        const nlohmann::json b = baselineOf(r);
        const auto* m = findMethod(r, name);
        if (b.is_null() || !m || m->contains("skipped"))
          t += fmt::format("{:>16}", "-");
        else
          t += fmt::format("{:>15.1f}x", b["frame_ms"].get<double>() / (*m)["frame_ms"]["median"].get<double>());
      }
      t += "\n";
    }
  };
  t += tenthsTable(rows, names, kName);
  t += parallelTable(rows, names, kName);
  accelerationBlock("Acceleration over the FASTEST of Bullet and the peers in the same run (of those that found "
                    "every pair; named per column)",
                    [](const nlohmann::json& r) { return r["fastest_baseline"]; });
  std::vector<std::string> libraries;
  for (const auto& r : rows)
    for (const auto& [lib, b] : r["fastest_per_library"].items())
      if (std::find(libraries.begin(), libraries.end(), lib) == libraries.end()) libraries.push_back(lib);
  for (const auto& lib : libraries)
    accelerationBlock("Acceleration over the fastest of " + lib + " (named per column)", [&](const nlohmann::json& r) {
      return r["fastest_per_library"].contains(lib) ? r["fastest_per_library"][lib] : nlohmann::json();
    });

  t += "\nExact pairs per frame (mean):";
  for (const auto& r : rows)
    t += fmt::format(" n={}: {:.0f}", r["objects"].get<std::size_t>(), r["exact_pairs_per_frame_mean"].get<double>());
  t += "\nExtra and missing pairs of Bullet and the peers over all frames (extra: padded or quantised boxes; a "
       "missing pair is a finding):";
  for (const auto& r : rows)
    for (const auto& m : r["methods"])
      if ((m["kind"] == "bullet" || m["kind"] == "peer") && !m.contains("skipped"))
        t += fmt::format("\n  n={} {}: extra {}, duplicates {}, missing {}{}", r["objects"].get<std::size_t>(),
                         m["name"].get<std::string>(), m["extra_pairs"].get<std::uint64_t>(),
                         m["duplicate_pairs"].get<std::uint64_t>(), m["missing_pairs"].get<std::uint64_t>(),
                         m["missing_pairs"].get<std::uint64_t>() ? "  <-- INEXACT: not a fair competitor" : "");
  bool anySkipped = false;
  for (const auto& r : rows)
    for (const auto& m : r["methods"])
      if (m.contains("skipped")) {
        if (!anySkipped) t += "\nSkipped:";
        anySkipped = true;
        t += fmt::format("\n  n={} {}: skipped: {}", r["objects"].get<std::size_t>(), m["name"].get<std::string>(),
                         m["skipped"].get<std::string>());
      }
  t += "\nWhere the time went, s of wall time (scene set-up, physics steps, exact reference, validation; set-up, "
       "timed updates and teardown summed over methods):";
  for (const auto& r : rows) {
    const auto& ts = r["time_s"];
    const auto sum = [](const nlohmann::json& parts) {
      double s = 0;
      for (const auto& [k, v] : parts.items()) s += v.get<double>();
      return s;
    };
    std::string slowest;  // the method whose set-up took longest
    double slowestSetup = -1;
    for (const auto& [k, v] : ts["method_setup"].items())
      if (v.get<double>() > slowestSetup) {
        slowestSetup = v.get<double>();
        slowest = k;
      }
    t += fmt::format("\n  n={}: scene {:.2f}, physics {:.2f}, reference {:.2f}, validation {:.2f}, method set-up "
                     "{:.2f} (longest: {} {:.2f}), method updates {:.2f}, teardown {:.2f}",
                     r["objects"].get<std::size_t>(), ts["scene_setup"].get<double>(), ts["physics_steps"].get<double>(),
                     ts["exact_reference"].get<double>(), ts["validation"].get<double>(), sum(ts["method_setup"]),
                     slowest, slowestSetup, sum(ts["method_updates"]), sum(ts["method_teardown"]));
  }
  t += "\n";
  if (results.contains("whole_step") && results["whole_step"].is_object()) t += wholeStepTable(results["whole_step"]);
  if (results.contains("queries")) t += queryTable(results["queries"]);
  if (results.contains("many_worlds")) t += manyWorldsTable(results["many_worlds"]);
  return t;
}

}  // namespace bpaccel
