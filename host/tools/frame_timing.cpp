// frame_timing: the accelerator method's host work per frame, by part, on the
// benchmark's scene (bouncing cube), outside the unit tests.
//
//   frame_timing [--objects 8000] [--cell-size 128] [--partition grid|kd] [--cells-per-batch 16]
//                [--backend model|rtl|cpu] [--frames 30] [--passes 10] [--evict]
//
// The scene is simulated once and its frames recorded; then every pass runs
// BroadPhase over the recorded frames in order (as the benchmark hands them
// over, frame after frame) and every frame's pairs are checked against the
// exact set. Host work = the frame's measured time minus the time inside the
// backend, as the benchmark's accelerator rows count it. --evict touches a
// buffer larger than the caches before each frame, as the benchmark's other
// methods do between two frames of this one.

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <new>
#include <memory>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "backend.hpp"
#include "broad_phase.hpp"
#include "exact_pairs.hpp"
#include "rtl_backend.hpp"
#include "scene.hpp"

// Heap allocations, counted to report those a frame makes (a frame should
// reuse its buffers). Global only in this driver, for the replaced operator new.
std::size_t gAllocations = 0;

void* operator new(std::size_t size) {
  ++gAllocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return (v[(v.size() - 1) / 2] + v[v.size() / 2]) / 2;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Host work per frame of the accelerator method, by part, on the benchmark's scene"};
  std::size_t objects = 8000, cellSize = 128, cellsPerBatch = 16, frames = 30, passes = 10;
  std::string partition = "grid", backendName = "model";
  bool evict = false;
  app.add_option("--objects", objects)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--cell-size", cellSize)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--partition", partition)->capture_default_str()->check(CLI::IsMember({"kd", "grid"}));
  app.add_option("--cells-per-batch", cellsPerBatch)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--backend", backendName)->capture_default_str()->check(CLI::IsMember({"model", "rtl", "cpu"}));
  app.add_option("--frames", frames, "Frames recorded (each timed once a pass)")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--passes", passes, "Passes over the recorded frames")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("--evict", evict, "Evict the caches before each frame");
  CLI11_PARSE(app, argc, argv);

  bpaccel::SceneConfig sc;
  sc.objects = objects;
  bpaccel::BouncingCubeScene scene(sc);
  std::vector<std::vector<bpaccel::Aabb>> recorded(frames);
  for (std::size_t w = 0; w < 5; ++w) scene.step();  // the benchmark's warm-up frames
  for (auto& f : recorded) {
    scene.step();
    scene.aabbs(f);
  }
  std::vector<std::vector<bpaccel::Pair>> exact(frames);
  for (std::size_t f = 0; f < frames; ++f) bpaccel::exactPairs(recorded[f], exact[f]);

  std::unique_ptr<bpaccel::Backend> backend;
  if (backendName == "rtl")
    backend = std::make_unique<bpaccel::RtlBackend>();
  else if (backendName == "cpu")  // software all-pairs: the host's own parts stand out in a profile
    backend = std::make_unique<bpaccel::CpuBackend>();
  else
    backend = std::make_unique<bpaccel::ModelBackend>(bpaccel::modelOfBuiltHardware());
  bpaccel::BroadPhase phase(*backend, cellSize, cellsPerBatch, bpaccel::parsePartitionKind(partition));

  std::vector<char> flood(evict ? 64u << 20 : 0);
  std::vector<double> host, convert, part, cells, decode, allocations;  // allocations: after the first pass
  std::vector<bpaccel::Pair> pairs;
  unsigned sink = 0;
  for (std::size_t p = 0; p < passes; ++p) {
    for (std::size_t f = 0; f < frames; ++f) {
      for (std::size_t b = 0; b < flood.size(); b += 64) sink += static_cast<unsigned char>(++flood[b]);
      const std::size_t allocationsBefore = gAllocations;
      const auto t0 = Clock::now();
      phase.findPairs(recorded[f], pairs);
      const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
      const auto& t = phase.times();
      host.push_back(wall - t.backendSeconds);
      if (p > 0) allocations.push_back(static_cast<double>(gAllocations - allocationsBefore));
      convert.push_back(t.convertSeconds);
      part.push_back(t.partitionSeconds);
      cells.push_back(t.cellsSeconds - t.backendSeconds);
      double decoded = 0;
      for (const auto& r : phase.runs()) decoded += r.decodeSeconds;
      decode.push_back(decoded);
      std::sort(pairs.begin(), pairs.end());
      if (pairs != exact[f]) {
        fmt::print(stderr, "frame_timing: frame {} pass {}: {} pairs, the exact set has {}\n", f, p, pairs.size(),
                   exact[f].size());
        return 1;
      }
    }
  }
  const auto us = [](const std::vector<double>& v) { return median(v) * 1e6; };
  fmt::print("objects {} partition {} cell {} cells/batch {} backend {} frames {} evict {} (sink {})\n", objects,
             partition, cellSize, cellsPerBatch, backend->name(), host.size(), evict, sink & 1);
  fmt::print("host_us {:.1f} convert_us {:.1f} partition_us {:.1f} cells_host_us {:.1f} (decode_us {:.1f}) pairs {} hits {} runs {} batches {} allocations/frame {}\n",
             us(host), us(convert), us(part), us(cells), us(decode), pairs.size(), phase.stats().hits, phase.stats().runs, phase.stats().batches, median(allocations));
  return 0;
}
