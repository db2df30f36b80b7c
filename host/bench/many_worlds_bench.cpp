#include "many_worlds_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>

#include <btBulletCollisionCommon.h>
#include <fmt/format.h>

#include "benchmark.hpp"
#include "broad_phase/many_worlds.hpp"
#include "core/median.hpp"
#include "device/cpu_backend.hpp"
#include "scenes/exact_pairs.hpp"
#include "model/link_model.hpp"
#include "peers/bullet_methods.hpp"
#include "peers/fcl_managers.hpp"
#include "scenes/scene_families.hpp"

namespace bpaccel {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

BouncingWorlds::BouncingWorlds(std::size_t worlds, std::size_t boxesPerWorld, const SceneConfig& cube)
    : perWorld_(boxesPerWorld), timeStep_(cube.timeStep) {
  if (worlds == 0 || boxesPerWorld == 0) throw std::invalid_argument("many worlds: at least one world of one box");
  SceneConfig one = cube;
  one.objects = boxesPerWorld;
  edge_ = one.cubeEdge();
  std::mt19937 rng(cube.seed);
  const auto uni = [&](float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); };
  bodies_.resize(worlds * boxesPerWorld);
  for (Body& b : bodies_) {
    for (int a = 0; a < 3; ++a) {
      b.half[a] = uni(cube.minSize, cube.maxSize) / 2;
      b.velocity[a] = uni(-cube.maxSpeed, cube.maxSpeed);
    }
    b.reach = std::sqrt(b.half[0] * b.half[0] + b.half[1] * b.half[1] + b.half[2] * b.half[2]);
    if (2 * b.reach >= edge_) throw std::invalid_argument("many worlds: a box does not fit its world's cube");
    for (int a = 0; a < 3; ++a) b.centre[a] = uni(b.reach, edge_ - b.reach);
    b.spinAxis = static_cast<int>(rng() % 3);
    b.angle = uni(0, 2 * std::numbers::pi_v<float>);
    b.spin = uni(-cube.maxSpin, cube.maxSpin);
  }
  boxes_.resize(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k) boxOf(bodies_[k], boxes_[k]);
}

void BouncingWorlds::boxOf(const Body& b, Aabb& out) const {
  const std::array<float, 3> half = turnedHalfExtents(b.half, b.spinAxis, b.angle);
  for (int k = 0; k < 3; ++k) {
    // Clamped so that rounding cannot carry a box past the cube's walls.
    out.min[k] = std::max(b.centre[k] - half[k], 0.0f);
    out.max[k] = std::min(b.centre[k] + half[k], edge_);
  }
}

void BouncingWorlds::step() {
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    Body& b = bodies_[k];
    b.angle += b.spin * timeStep_;
    for (int a = 0; a < 3; ++a) {
      b.centre[a] += b.velocity[a] * timeStep_;
      const float lo = b.reach, hi = edge_ - b.reach;  // the walls, for its centre
      if (b.centre[a] < lo) {
        b.centre[a] = 2 * lo - b.centre[a];
        b.velocity[a] = std::abs(b.velocity[a]);
      } else if (b.centre[a] > hi) {
        b.centre[a] = 2 * hi - b.centre[a];
        b.velocity[a] = -std::abs(b.velocity[a]);
      }
    }
    boxOf(b, boxes_[k]);
  }
}

namespace {

// A device backend whose calls are timed: simulating the device is not host work.
class TimedBackend final : public Backend {
 public:
  explicit TimedBackend(std::unique_ptr<Backend> inner) : inner_(std::move(inner)) {}
  std::string name() const override { return inner_->name(); }
  std::size_t capacity() const override { return inner_->capacity(); }
  unsigned keyWidth() const override { return inner_->keyWidth(); }
  void run(std::span<const KeyBox> boxes, std::vector<Pair>& out, RunStats& stats) override {
    const auto t0 = Clock::now();
    inner_->run(boxes, out, stats);
    seconds_ += since(t0);
  }
  void runBatch(std::span<const std::span<const KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<Pair>& out, std::vector<std::size_t>& cellEnds, RunStats& stats) override {
    const auto t0 = Clock::now();
    inner_->runBatch(cells, splits, out, cellEnds, stats);
    seconds_ += since(t0);
  }
  double takeSeconds() { return std::exchange(seconds_, 0.0); }

 private:
  std::unique_ptr<Backend> inner_;
  double seconds_ = 0;
};

// ManyWorlds on a backend: the worlds batched as cells. A device's backend is
// timed, so that its simulation is taken out of the host's time.
class ManyWorldsMethod final : public WorldsMethod {
 public:
  ManyWorldsMethod(std::unique_ptr<Backend> backend, bool device)
      : timed_(device ? new TimedBackend(std::move(backend)) : nullptr),
        backend_(timed_ ? std::unique_ptr<Backend>(timed_) : std::move(backend)),
        worlds_(*backend_) {}
  void update(std::span<const std::span<const Aabb>> worlds) override {
    worlds_.findPairs(worlds, pairs_);
    if (timed_) simulated_ = timed_->takeSeconds();
  }
  void pairs(std::size_t w, std::vector<Pair>& out) override {
    const auto p = pairs_.of(w);
    out.assign(p.begin(), p.end());
  }
  const RunStats* deviceStats() const override { return timed_ ? &worlds_.stats() : nullptr; }
  double deviceSimulationSeconds() const override { return simulated_; }

 private:
  TimedBackend* timed_;  // owned by backend_; null on the cpu backend
  std::unique_ptr<Backend> backend_;
  ManyWorlds worlds_;
  WorldPairs pairs_;
  double simulated_ = 0;
};

// One TimedMethod per world, built from a line-up's factory (a peer as each
// world would keep it).
class PerWorldMethod final : public WorldsMethod {
 public:
  using Make = std::function<std::unique_ptr<TimedMethod>(const SceneStart&)>;
  PerWorldMethod(std::span<const std::span<const Aabb>> first, float edge, const Make& make,
                 std::shared_ptr<void> shared = nullptr)
      : shared_(std::move(shared)) {
    for (const auto& world : first)
      methods_.push_back(make(SceneStart{world, 0, edge, {0, 0, 0}, {edge, edge, edge}}));
  }
  void update(std::span<const std::span<const Aabb>> worlds) override {
    for (std::size_t w = 0; w < worlds.size(); ++w) methods_[w]->update(worlds[w]);
  }
  void pairs(std::size_t w, std::vector<Pair>& out) override { methods_[w]->pairs(out); }

 private:
  std::shared_ptr<void> shared_;  // what the methods share: destroyed after them
  std::vector<std::unique_ptr<TimedMethod>> methods_;
};

// One collision configuration and dispatcher for every world's btDbvtBroadphase
// (each of its own would hold megabytes of pools, 4096 times over).
struct SharedDispatcher {
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
};

WorldsMethodSpec perWorld(std::string name, MethodKind kind, std::string library, PerWorldMethod::Make make) {
  return {std::move(name), kind, std::move(library), nullptr,
          [make](std::span<const std::span<const Aabb>> first, float edge) {
            return std::make_unique<PerWorldMethod>(first, edge, make);
          }};
}

}  // namespace

std::vector<WorldsMethodSpec> manyWorldsLineUp(const std::shared_ptr<const DeviceConfig>& device) {
  std::vector<WorldsMethodSpec> specs;
  specs.push_back({"cpu ManyWorlds", MethodKind::Cpu, "bpaccel", nullptr,
                   [](std::span<const std::span<const Aabb>>, float) {
                     return std::make_unique<ManyWorldsMethod>(std::make_unique<CpuBackend>(), false);
                   }});
  specs.push_back({"btDbvtBroadphase, one per world", MethodKind::Bullet, "Bullet 3.24", nullptr,
                   [](std::span<const std::span<const Aabb>> first, float edge) {
                     auto shared = std::make_shared<SharedDispatcher>();
                     btCollisionDispatcher* dispatcher = &shared->dispatcher;
                     return std::make_unique<PerWorldMethod>(
                         first, edge,
                         [dispatcher](const SceneStart& s) {
                           return std::make_unique<BulletMethod>(BulletMethod::Kind::Dbvt, s.boxes, s.worldMin,
                                                                 s.worldMax, dispatcher);
                         },
                         shared);
                   }});
  for (const MethodSpec& fcl : fclMethods(1e18))
    if (fcl.name.starts_with("FCL DynamicAABBTree"))
      specs.push_back(perWorld(fcl.name + ", one per world", MethodKind::Peer, fcl.library, fcl.make));
  if (device) {
    const std::size_t capacity = device->makeBackend()->capacity();
    specs.push_back({"accelerator ManyWorlds", MethodKind::Accelerator, "bpaccel",
                     [capacity](std::size_t boxes) -> std::optional<std::string> {
                       if (boxes <= capacity) return std::nullopt;
                       return fmt::format("a world of {} boxes exceeds the device's capacity of {}", boxes, capacity);
                     },
                     [device](std::span<const std::span<const Aabb>>, float) {
                       return std::make_unique<ManyWorldsMethod>(device->makeBackend(), true);
                     }});
  }
  return specs;
}

namespace {

// One method of one row: what it was timed at, and how its pairs compared.
struct WorldsEntry {
  const WorldsMethodSpec* spec = nullptr;
  std::unique_ptr<WorldsMethod> method;
  std::optional<std::string> skipped;
  std::vector<double> seconds, hostSeconds;  // per timed frame: wall, and wall minus the device's simulation
  std::vector<RunStats> stats;               // per timed frame, device methods only
  std::uint64_t missing = 0, extra = 0;
};

// Every world's pairs of the method's last update against the exact sets.
void validate(WorldsEntry& e, const std::vector<std::vector<Pair>>& exact, std::size_t boxes, std::size_t frame) {
  std::vector<Pair> got;
  for (std::size_t w = 0; w < exact.size(); ++w) {
    e.method->pairs(w, got);
    std::sort(got.begin(), got.end());
    got.erase(std::unique(got.begin(), got.end()), got.end());
    const SetDifference d = compareSorted(got, exact[w]);
    if (mustBeExact(e.spec->kind) && (d.missing || d.extra))
      throw ValidationFailure(fmt::format("{} (world {})", e.spec->name, w), boxes, frame, d, exact[w].size());
    e.missing += d.missing;
    e.extra += d.extra;
  }
}

nlohmann::json entryJson(const WorldsEntry& e, const std::string& name, const std::vector<double>& seconds) {
  nlohmann::json j = {{"name", name}, {"kind", kindName(e.spec->kind)}, {"library", e.spec->library}};
  if (e.skipped) {
    j["skipped"] = *e.skipped;
    return j;
  }
  j["frame_ms"] = summary(seconds, 1e3);
  j["missing_pairs"] = e.missing;
  j["extra_pairs"] = e.extra;
  return j;
}

// The accelerator's one measured run, modelled on each profile (or on the
// device's own clock and link): host measured, device and link modelled.
void addModelledRows(const WorldsEntry& e, const ManyWorldsBenchConfig& config, nlohmann::json& methods) {
  std::vector<std::pair<std::string, DeviceConfig>> platforms;
  if (config.profiles.empty()) platforms.emplace_back("", *config.device);
  for (const auto& p : config.profiles) platforms.emplace_back(" on " + p.name, withProfile(*config.device, p));
  for (const auto& [suffix, d] : platforms) {
    std::vector<double> frame, device, transfer;
    for (std::size_t f = 0; f < e.stats.size(); ++f) {
      device.push_back(static_cast<double>(e.stats[f].deviceCycles()) / d.clockHz);
      transfer.push_back(transferSeconds(e.stats[f], d.link, d.clockHz));
      frame.push_back(e.hostSeconds[f] + device.back() + transfer.back());
    }
    nlohmann::json j = entryJson(e, e.spec->name + suffix, frame);
    if (d.profile) j["profile"] = d.profile->toJson();
    j["modelled"] = fmt::format("host measured; device cycles ({} backend) / {:.2f} MHz and link modelled{}",
                                d.backend, d.clockHz / 1e6, d.profile ? " on profile " + d.profile->summary() : "");
    if (!e.skipped) {
      j["host_ms_measured"] = summary(e.hostSeconds, 1e3);
      j["device_ms_modelled"] = summary(device, 1e3);
      j["transfer_ms_modelled"] = summary(transfer, 1e3);
      j["batches"] = e.stats.empty() ? 0 : e.stats.back().batches;
    }
    methods.push_back(j);
  }
}

nlohmann::json worldsRow(const ManyWorldsBenchConfig& config, const std::vector<WorldsMethodSpec>& lineUp,
                         std::size_t boxes, const std::function<void(const std::string&)>& progress) {
  BouncingWorlds scene(config.worlds, boxes, config.scene);
  const auto spans = [&] {
    std::vector<std::span<const Aabb>> v;
    for (std::size_t w = 0; w < scene.worlds(); ++w) v.push_back(scene.world(w));
    return v;
  };
  std::vector<WorldsEntry> entries(lineUp.size());
  for (std::size_t k = 0; k < lineUp.size(); ++k) {
    WorldsEntry& e = entries[k];
    e.spec = &lineUp[k];
    if (e.spec->skipReason) e.skipped = e.spec->skipReason(boxes);
    progress(fmt::format("many worlds, {} x {}: {}: {}", config.worlds, boxes, e.spec->name,
                         e.skipped ? "skipped: " + *e.skipped : std::string("set-up")));
    if (!e.skipped) e.method = e.spec->make(spans(), scene.edge());
  }
  std::vector<std::vector<Pair>> exact(config.worlds);
  std::uint64_t exactTotal = 0;
  std::mt19937 shuffler(config.scene.seed);
  std::vector<std::size_t> order(entries.size());
  std::iota(order.begin(), order.end(), 0);
  for (std::size_t frame = 0; frame < config.warmup + config.frames; ++frame) {
    const bool timed = frame >= config.warmup;
    scene.step();
    const auto worlds = spans();
    for (std::size_t w = 0; w < worlds.size(); ++w) {
      exactPairs(worlds[w], exact[w]);
      if (timed) exactTotal += exact[w].size();
    }
    std::shuffle(order.begin(), order.end(), shuffler);
    for (std::size_t k : order) {
      WorldsEntry& e = entries[k];
      if (e.skipped) continue;
      const auto t0 = Clock::now();
      e.method->update(worlds);
      const double wall = since(t0);
      validate(e, exact, boxes, frame);
      if (!timed) continue;
      e.seconds.push_back(wall);
      if (const RunStats* s = e.method->deviceStats()) {
        e.stats.push_back(*s);
        e.hostSeconds.push_back(wall - e.method->deviceSimulationSeconds());
      }
    }
  }
  nlohmann::json methods = nlohmann::json::array();
  for (const WorldsEntry& e : entries) {
    if (e.spec->kind == MethodKind::Accelerator && config.device)
      addModelledRows(e, config, methods);
    else
      methods.push_back(entryJson(e, e.spec->name, e.seconds));
  }
  return {{"boxes_per_world", boxes},
          {"cube_edge", scene.edge()},
          {"exact_pairs_per_frame_mean", static_cast<double>(exactTotal) / static_cast<double>(config.frames)},
          {"methods", methods}};
}

}  // namespace

nlohmann::json runManyWorldsBench(const ManyWorldsBenchConfig& config, const std::vector<WorldsMethodSpec>& lineUp,
                                  const std::function<void(const std::string&)>& progress) {
  if (config.worlds == 0 || config.frames == 0) throw std::invalid_argument("many worlds: at least one world and frame");
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t n : config.boxesPerWorld) rows.push_back(worldsRow(config, lineUp, n, progress));
  return {{"worlds", config.worlds},
          {"frames", config.frames},
          {"warmup_frames", config.warmup},
          {"what", "every world's boxes move each frame (kinematic bouncing cube per world: the bench's box sizes, "
                   "density and speeds, turning, bouncing off the walls); frame_ms covers all worlds; every world's "
                   "pairs compared with the exact set (cpu and accelerator must equal it); accelerator rows: one "
                   "measured host run, device and link MODELLED per profile"},
          {"rows", rows}};
}

std::string manyWorldsTable(const nlohmann::json& j) {
  const auto& rows = j["rows"];
  std::string t = fmt::format(
      "\nMany worlds: {} worlds of n boxes each, all moving, every world's pairs validated; ms a frame for all "
      "worlds, median over {} frames, and the cpu backend's time over it (x); accelerator rows: measured host + "
      "MODELLED device and link on the named profile\n{:<52}",
      j["worlds"].get<std::size_t>(), j["frames"].get<std::size_t>(), "method");
  for (const auto& r : rows) t += fmt::format("{:>22}", fmt::format("n={}", r["boxes_per_world"].get<std::size_t>()));
  t += "\n";
  std::vector<std::string> names;
  for (const auto& r : rows)
    for (const auto& m : r["methods"])
      if (std::find(names.begin(), names.end(), m["name"]) == names.end()) names.push_back(m["name"]);
  for (const auto& name : names) {
    t += fmt::format("{:<52}", name);
    for (const auto& r : rows) {
      const nlohmann::json* mine = nullptr;
      double cpu = 0;
      for (const auto& m : r["methods"]) {
        if (m["name"] == name) mine = &m;
        if (m["kind"] == "cpu" && m.contains("frame_ms")) cpu = m["frame_ms"]["median"].get<double>();
      }
      if (!mine || !mine->contains("frame_ms")) {
        t += fmt::format("{:>22}", "-");
        continue;
      }
      const double ms = (*mine)["frame_ms"]["median"].get<double>();
      const bool missed = (*mine)["missing_pairs"].get<std::uint64_t>() > 0;
      t += fmt::format("{:>22}", fmt::format("{:.3f}{} ({:.2f}x)", ms, missed ? "!" : "", cpu / ms));
    }
    t += "\n";
  }
  for (const auto& r : rows)
    for (const auto& m : r["methods"])
      if (m.contains("skipped"))
        t += fmt::format("  n={} {}: skipped: {}\n", r["boxes_per_world"].get<std::size_t>(),
                         m["name"].get<std::string>(), m["skipped"].get<std::string>());
  return t;
}

}  // namespace bpaccel
