#include "benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <thread>

#include <fmt/format.h>

#include "backend.hpp"
#include "bpaccel_params.h"
#include "broad_phase.hpp"
#include "bullet_broadphase.hpp"
#include "exact_pairs.hpp"
#include "rtl_backend.hpp"

namespace bpaccel {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string cellName(const std::optional<std::size_t>& c) { return c ? std::to_string(*c) : "none"; }

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : (v[h - 1] + v[h]) / 2;
}

nlohmann::json summary(const std::vector<double>& v, double scale) {
  if (v.empty()) return nullptr;
  return {{"median", median(v) * scale},
          {"min", *std::min_element(v.begin(), v.end()) * scale},
          {"max", *std::max_element(v.begin(), v.end()) * scale}};
}

// Bytes of one result beat: {iBase, jBase, mask[m]}, rounded up to bytes.
std::size_t beatBytes() { return (2 * BPACCEL_INDEX_WIDTH + BPACCEL_M + 7) / 8; }

std::string machineDescription() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

}  // namespace

double LinkModel::seconds(const RunStats& s, std::size_t bytesPerBeat) const {
  const double bytes = 24.0 * static_cast<double>(s.boxesSent) + static_cast<double>(bytesPerBeat * s.beatsReceived);
  return static_cast<double>(s.runs) * latencySecondsPerRun + bytes / bandwidthBytesPerSecond;
}

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

Benchmark::Benchmark(BenchConfig config, Progress progress) : config_(std::move(config)), progress_(std::move(progress)) {
  if (config_.frames == 0) throw std::invalid_argument("bench: at least one timed frame");
  if (config_.accelBackend != "rtl" && config_.accelBackend != "model")
    throw std::invalid_argument("bench: accelerator backend must be rtl or model");
  if (!(config_.clockHz > 0)) throw std::invalid_argument("bench: clock must be positive");
}

nlohmann::json Benchmark::run() {
  nlohmann::json out;
  nlohmann::json cells = nlohmann::json::array();
  for (const auto& c : config_.cellSizes) cells.push_back(cellName(c));
  out["configuration"] = {
      {"object_counts", config_.objectCounts},
      {"cell_sizes", cells},
      {"accelerator_backend", config_.accelBackend},
      {"frames", config_.frames},
      {"warmup_frames", config_.warmup},
      {"scene",
       {{"min_size", config_.scene.minSize},
        {"max_size", config_.scene.maxSize},
        {"density_objects_per_unit3", config_.scene.density},
        {"max_speed", config_.scene.maxSpeed},
        {"max_spin", config_.scene.maxSpin},
        {"time_step", config_.scene.timeStep},
        {"seed", config_.scene.seed}}},
      {"hardware",
       {{"m", BPACCEL_M},
        {"capacity", BPACCEL_CAPACITY},
        {"key_width", BPACCEL_KEY_WIDTH},
        {"run_overhead_cycles", BPACCEL_RUN_OVERHEAD_CYCLES},
        {"fingerprint", BPACCEL_FINGERPRINT}}},
      {"clock_hz", config_.clockHz},
      {"clock_source", config_.clockSource},
      {"link_model",
       {{"bandwidth_bytes_per_second", config_.link.bandwidthBytesPerSecond},
        {"latency_seconds_per_run", config_.link.latencySecondsPerRun},
        {"bytes_per_box", 24},
        {"bytes_per_result_beat", beatBytes()}}},
  };
  out["machine"] = {{"cpu", machineDescription()},
                    {"hardware_threads", std::thread::hardware_concurrency()},
                    {"compiler", __VERSION__},
                    {"bullet", "3.24 (Debian libbullet-dev)"}};
  out["notes"] = {
      {"measured", "Bullet broad phases, cpu backend, accelerator host part (float-to-key conversion, k-d tree, "
                   "packing, remapping and filtering pairs)"},
      {"modelled", "accelerator device part (hardware cycles / clock) and transfer part (link model)"}};
  out["rows"] = nlohmann::json::array();
  for (std::size_t n : config_.objectCounts) out["rows"].push_back(runRow(n));
  out["validation"] = "every frame: accelerator and cpu pair sets equal the exact set";
  return out;
}

nlohmann::json Benchmark::runRow(std::size_t objects) {
  SceneConfig sc = config_.scene;
  sc.objects = objects;
  BouncingCubeScene scene(sc);
  std::vector<Aabb> boxes;
  scene.aabbs(boxes);

  const float margin = 2 * sc.maxSize + 2;
  std::vector<std::unique_ptr<BulletBroadphase>> bullets;
  for (auto kind : {BulletBroadphase::Kind::Dbvt, BulletBroadphase::Kind::AxisSweep32, BulletBroadphase::Kind::Simple})
    if (kind != BulletBroadphase::Kind::Simple || config_.includeSimple)
      bullets.push_back(std::make_unique<BulletBroadphase>(kind, boxes, -margin, scene.cubeEdge() + margin));

  std::unique_ptr<Backend> accel;
  if (config_.accelBackend == "rtl")
    accel = std::make_unique<RtlBackend>();
  else
    accel = std::make_unique<ModelBackend>(BPACCEL_M, BPACCEL_CAPACITY, BPACCEL_RUN_OVERHEAD_CYCLES);
  CpuBackend cpu;
  std::vector<std::unique_ptr<BroadPhase>> accelPhases, cpuPhases;
  std::vector<MethodSamples> samples;
  const auto method = [](std::string name, std::string kind, std::optional<std::size_t> cell) {
    MethodSamples m;
    m.name = std::move(name);
    m.kind = std::move(kind);
    m.cellSize = cell;
    return m;
  };
  for (const auto& b : bullets) samples.push_back(method(BulletBroadphase::name(b->kind()), "bullet", std::nullopt));
  for (const auto& c : config_.cellSizes) {
    accelPhases.push_back(std::make_unique<BroadPhase>(*accel, c));
    samples.push_back(method("accelerator k-d " + cellName(c), "accelerator", c));
  }
  for (const auto& c : config_.cellSizes) {
    cpuPhases.push_back(std::make_unique<BroadPhase>(cpu, c));
    samples.push_back(method("cpu k-d " + cellName(c), "cpu", c));
  }

  std::vector<Pair> exact, got;
  std::uint64_t exactTotal = 0;
  const std::size_t totalFrames = config_.warmup + config_.frames;
  const double energyStart = scene.kineticEnergy();
  for (std::size_t frame = 0; frame < totalFrames; ++frame) {
    const bool timed = frame >= config_.warmup;
    progress_(fmt::format("n={} frame {}/{}{}", objects, frame + 1, totalFrames, timed ? "" : " (warm-up)"));
    scene.step();
    scene.aabbs(boxes);
    exactPairs(boxes, exact);
    if (timed) exactTotal += exact.size();
    std::size_t s = 0;

    for (auto& b : bullets) {
      auto& m = samples[s++];
      const auto t0 = Clock::now();
      b->update(boxes);
      const double t = since(t0);
      b->pairs(got);
      std::sort(got.begin(), got.end());
      const auto d = compareSorted(got, exact);
      if (timed) {
        m.frameSeconds.push_back(t);
        m.missing += d.missing;
        m.extra += d.extra;
      }
    }

    for (auto& phase : accelPhases) {
      auto& m = samples[s++];
      const auto t0 = Clock::now();
      phase->findPairs(boxes, got);
      const double wall = since(t0);
      const HostTimes& ht = phase->times();
      const RunStats& st = phase->stats();
      const double host = wall - ht.backendSeconds;  // the device's simulation is not host work
      const double device = static_cast<double>(st.cycles) / config_.clockHz;
      const double transfer = config_.link.seconds(st, beatBytes());
      if (config_.tamper) config_.tamper(got);
      std::sort(got.begin(), got.end());
      const auto d = compareSorted(got, exact);
      if (d.missing || d.extra)
        throw ValidationFailure(fmt::format("n={} frame {}: {} gave {} missing and {} extra pairs against the exact "
                                            "set of {}",
                                            objects, frame, m.name, d.missing, d.extra, exact.size()));
      if (timed) {
        m.hostSeconds.push_back(host);
        m.deviceSeconds.push_back(device);
        m.transferSeconds.push_back(transfer);
        m.frameSeconds.push_back(host + device + transfer);
        m.cycles.push_back(static_cast<double>(st.cycles));
        m.runs.push_back(static_cast<double>(st.runs));
      }
    }

    for (auto& phase : cpuPhases) {
      auto& m = samples[s++];
      const auto t0 = Clock::now();
      phase->findPairs(boxes, got);
      const double t = since(t0);
      std::sort(got.begin(), got.end());
      const auto d = compareSorted(got, exact);
      if (d.missing || d.extra)
        throw ValidationFailure(fmt::format("n={} frame {}: {} gave {} missing and {} extra pairs", objects, frame,
                                            m.name, d.missing, d.extra));
      if (timed) m.frameSeconds.push_back(t);
    }
  }

  nlohmann::json row;
  row["objects"] = objects;
  row["cube_edge"] = scene.cubeEdge();
  row["exact_pairs_per_frame_mean"] = static_cast<double>(exactTotal) / static_cast<double>(config_.frames);
  row["kinetic_energy_start_end"] = {energyStart, scene.kineticEnergy()};
  double fastestBullet = INFINITY;
  std::string fastestName;
  for (const auto& m : samples)
    if (m.kind == "bullet" && median(m.frameSeconds) < fastestBullet) {
      fastestBullet = median(m.frameSeconds);
      fastestName = m.name;
    }
  row["fastest_bullet"] = fastestName;
  nlohmann::json methods = nlohmann::json::array();
  for (const auto& m : samples) {
    nlohmann::json j;
    j["name"] = m.name;
    j["kind"] = m.kind;
    j["cell_size"] = m.cellSize ? nlohmann::json(*m.cellSize) : nlohmann::json("none");
    j["frame_ms"] = summary(m.frameSeconds, 1e3);
    if (m.kind == "accelerator") {
      j["host_ms_measured"] = summary(m.hostSeconds, 1e3);
      j["device_ms_modelled"] = summary(m.deviceSeconds, 1e3);
      j["transfer_ms_modelled"] = summary(m.transferSeconds, 1e3);
      j["cycles"] = summary(m.cycles, 1);
      j["runs"] = summary(m.runs, 1);
    }
    if (m.kind == "bullet") {
      j["missing_pairs"] = m.missing;  // must be 0: Bullet's sets contain the exact set
      j["extra_pairs"] = m.extra;      // fattened or quantised boxes
    } else {
      j["missing_pairs"] = 0;
      j["extra_pairs"] = 0;
    }
    nlohmann::json acc;
    for (const auto& b : samples)
      if (b.kind == "bullet") acc[b.name] = median(b.frameSeconds) / median(m.frameSeconds);
    j["acceleration_over"] = acc;
    methods.push_back(j);
  }
  row["methods"] = methods;
  return row;
}

std::string Benchmark::table(const nlohmann::json& results) {
  std::string t;
  const auto& rows = results["rows"];
  if (rows.empty()) return t;
  // Methods as rows, object counts as columns, like the seed's table turned on its side.
  std::vector<std::string> names;
  for (const auto& m : rows[0]["methods"]) names.push_back(m["name"]);
  const auto header = [&](const std::string& title) {
    t += fmt::format("\n{}\n{:<28}", title, "method");
    for (const auto& r : rows) t += fmt::format("{:>16}", fmt::format("n={}", r["objects"].get<std::size_t>()));
    t += "\n";
  };
  header(fmt::format("Median broad-phase time per frame, ms (accelerator = measured host + modelled device at "
                     "{:.1f} MHz + modelled transfer; {} backend)",
                     results["configuration"]["clock_hz"].get<double>() / 1e6,
                     results["configuration"]["accelerator_backend"].get<std::string>()));
  for (const auto& name : names) {
    t += fmt::format("{:<28}", name);
    for (const auto& r : rows)
      for (const auto& m : r["methods"])
        if (m["name"] == name) t += fmt::format("{:>16.4f}", m["frame_ms"]["median"].get<double>());
    t += "\n";
  }
  for (const auto& bullet : rows[0]["methods"]) {
    if (bullet["kind"] != "bullet") continue;
    const std::string bname = bullet["name"];
    header("Acceleration over " + bname + " (its median / the method's median)");
    for (const auto& name : names) {
      if (name.rfind("bt", 0) == 0) continue;
      t += fmt::format("{:<28}", name);
      for (const auto& r : rows)
        for (const auto& m : r["methods"])
          if (m["name"] == name) t += fmt::format("{:>15.1f}x", m["acceleration_over"][bname].get<double>());
      t += "\n";
    }
  }
  t += "\nExact pairs per frame (mean):";
  for (const auto& r : rows) t += fmt::format(" n={}: {:.0f}", r["objects"].get<std::size_t>(), r["exact_pairs_per_frame_mean"].get<double>());
  t += "\nBullet extra pairs over all timed frames (fattened/quantised boxes; missing must be 0):";
  for (const auto& r : rows)
    for (const auto& m : r["methods"])
      if (m["kind"] == "bullet")
        t += fmt::format("\n  n={} {}: extra {}, missing {}", r["objects"].get<std::size_t>(), m["name"].get<std::string>(),
                         m["extra_pairs"].get<std::uint64_t>(), m["missing_pairs"].get<std::uint64_t>());
  t += "\n";
  return t;
}

}  // namespace bpaccel
