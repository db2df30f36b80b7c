// frame_timing: the accelerator method's host work per frame, by part, on the
// benchmark's scene (bouncing cube), outside the unit tests.
//
//   frame_timing [--objects 8000] [--cell-size 128] [--partition grid|kd] [--cells-per-batch 16]
//                [--first-batch-cells N ...] [--clock-mhz 100] [--backend model|rtl|cpu]
//                [--frames 30] [--passes 10] [--evict]
//
// The scene is simulated once and its frames recorded; then every pass runs
// BroadPhase over the recorded frames in order (as the benchmark hands them
// over, frame after frame) and every frame's pairs are checked against the
// exact set. Host work = the frame's measured time minus the time inside the
// backend, as the benchmark's accelerator rows count it. --evict touches a
// buffer larger than the caches before each frame, as the benchmark's other
// methods do between two frames of this one.
//
// --paced also runs each configuration's asynchronous hand-overs, both kinds
// (HandOvers::Asynchronous: the producer, the device's thread and a decoder
// thread; HandOvers::Polled: the producer decodes, and it and the device's
// thread poll instead of sleeping), against a device held for its modelled
// time (PacedBackend), and prints each frame's measured wall time beside the
// modelled overlapped frame of the same kind: a check of the model against
// the threads that run it. The paced device replays the model backend's
// answers recorded in the synchronous run of the same frame; only its
// duration is emulated.
//
// Several --first-batch-cells values are timed side by side: every frame runs
// each configuration in turn (in a rotating order), so that the machine's
// drift over a run falls on all of them alike. Each also prints the MODELLED
// overlapped frame (modelPipeline: the measured ready and decode times, the
// device's cycles at --clock-mhz, the benchmark's default link model).

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <new>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "device/model_backend.hpp"
#include "device/cpu_backend.hpp"
#include "device/async_backend.hpp"
#include "device/backend.hpp"
#include "broad_phase/broad_phase.hpp"
#include "core/median.hpp"
#include "scenes/exact_pairs.hpp"
#include "model/device_profile.hpp"
#include "model/paced_backend.hpp"
#include "device/rtl/rtl_backend.hpp"
#include "scenes/scene.hpp"
#include "model/timeline.hpp"

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
using bpaccel::median;

// Hand-over h's median span over the frames, in us: " from-to" each.
std::string medianSpans(const std::vector<std::vector<std::pair<double, double>>>& spans) {
  std::string line;
  for (std::size_t h = 0; h < spans.front().size(); ++h) {
    std::vector<double> from, to;
    for (const auto& frame : spans)
      if (h < frame.size()) {
        from.push_back(frame[h].first);
        to.push_back(frame[h].second);
      }
    line += fmt::format(" {:.0f}-{:.0f}", median(from) * 1e6, median(to) * 1e6);
  }
  return line;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Host work per frame of the accelerator method, by part, on the benchmark's scene"};
  std::size_t objects = 8000, cellSize = 128, cellsPerBatch = 16, frames = 30, passes = 10;
  std::string partition = "grid", backendName = "model";
  std::vector<std::size_t> firstBatchCells;
  std::vector<unsigned> keyWidths;
  double clockMHz = 100;
  std::string profileName = "gen3x8";
  bool evict = false;
  app.add_option("--objects", objects)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--cell-size", cellSize)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--partition", partition)->capture_default_str()->check(CLI::IsMember({"kd", "grid"}));
  app.add_option("--cells-per-batch", cellsPerBatch)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--first-batch-cells", firstBatchCells,
                 "Cells of each frame's first hand-over (BroadPhaseConfig::firstBatchCells); several: compared")
      ->check(CLI::PositiveNumber);
  app.add_option("--clock-mhz", clockMHz, "Device clock of the modelled overlapped frame")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--profile", profileName, "Device profile whose link the modelled frame uses (bpaccel-bench --profiles)")
      ->capture_default_str()->check(CLI::IsMember(bpaccel::builtInProfileNames()));
  app.add_option("--backend", backendName)->capture_default_str()->check(CLI::IsMember({"model", "rtl", "cpu"}));
  app.add_option("--frames", frames, "Frames recorded (each timed once a pass)")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--passes", passes, "Passes over the recorded frames")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("--evict", evict, "Evict the caches before each frame");
  bool paced = false;
  app.add_flag("--paced", paced,
               "Also run the asynchronous hand-overs against a device held for its modelled time, and time them "
               "(recording the synchronous run's answers adds to its allocations)");
  app.add_option("--key-width", keyWidths,
                 "Key widths of the model's device (default: the built hardware's); several: compared. "
                 "Below 32 the host narrows each cell's keys and checks the pairs")
      ->check(CLI::Range(1u, 32u));
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

  if (firstBatchCells.empty()) firstBatchCells.push_back(cellsPerBatch);
  const bpaccel::DeviceParams built = bpaccel::builtDeviceParams();
  const unsigned builtKeyWidth = built.keyWidth;
  if (keyWidths.empty()) keyWidths.push_back(builtKeyWidth);
  if (backendName != "model" && (keyWidths.size() > 1 || keyWidths.front() != builtKeyWidth)) {
    fmt::print(stderr, "frame_timing: --key-width other than the built hardware's ({}) needs --backend model\n",
               builtKeyWidth);
    return 2;
  }
  const auto makeBackend = [&](unsigned keyWidth) -> std::unique_ptr<bpaccel::Backend> {
    if (backendName == "rtl") return std::make_unique<bpaccel::RtlBackend>();
    if (backendName == "cpu")  // software all-pairs: the host's own parts stand out in a profile
      return std::make_unique<bpaccel::CpuBackend>();
    bpaccel::DeviceParams params = built;
    params.keyWidth = keyWidth;  // what narrower keys would cost the host, without building that hardware
    return std::make_unique<bpaccel::ModelBackend>(params);
  };
  // One configuration: its backend, its broad phase and its figures.
  struct Timed {
    std::unique_ptr<bpaccel::Backend> backend;
    std::unique_ptr<bpaccel::LastFrameTiming> timing = std::make_unique<bpaccel::LastFrameTiming>();
    std::unique_ptr<bpaccel::BroadPhase> phase;
    std::vector<double> host, convert, part, cells, decode, pipelined;
    std::vector<double> allocations;  // after the first pass
    unsigned keyWidth = 32;
    std::vector<double> pipelinedPolled;  // the modelled overlapped frame with the producer decoding
    std::vector<double> lastReady;        // when the synchronous run's last batch was ready
    // Per frame, the modelled device's span of each hand-over (producer decoding), s from the frame's start.
    std::vector<std::vector<std::pair<double, double>>> modelledSpans;
    // --paced: the same configuration's asynchronous hand-overs on a paced device, of each kind.
    struct Paced {
      bpaccel::LastFrameTiming timing;
      std::unique_ptr<bpaccel::PacedBroadPhase> phase;
      std::vector<double> wall, lastReady, waits, decode;
    };
    std::vector<std::unique_ptr<Paced>> paced;
    // The synchronous run's answers.
    std::unique_ptr<bpaccel::AnswerRecording> recording = std::make_unique<bpaccel::AnswerRecording>();
  };
  bpaccel::PipelineModel model;
  model.clockHz = clockMHz * 1e6;
  // Only the profile's link: the clock is --clock-mhz.
  model.link = bpaccel::builtInProfile(profileName, {}).linkModel(static_cast<double>(built.loadBoxBytes()),
                                                                  static_cast<double>(built.resultBeatBytes()));
  if (paced && (backendName != "model" || cellsPerBatch < 2)) {
    fmt::print(stderr, "frame_timing: --paced needs --backend model and --cells-per-batch of at least 2\n");
    return 2;
  }
  std::vector<Timed> timed;
  for (const std::size_t first : firstBatchCells)
    for (const unsigned keyWidth : keyWidths) {
      Timed t;
      t.keyWidth = keyWidth;
      t.backend = makeBackend(keyWidth);
      if (paced) t.backend = std::make_unique<bpaccel::RecordingBackend>(std::move(t.backend), *t.recording);
      const bpaccel::BroadPhaseConfig config{.cellSize = cellSize,
                                             .partition = bpaccel::parsePartitionKind(partition),
                                             .cellsPerBatch = cellsPerBatch,
                                             .firstBatchCells = first,
                                             .observer = t.timing.get()};
      t.phase = std::make_unique<bpaccel::BroadPhase>(*t.backend, config);
      if (paced) {
        bpaccel::PipelineModel deviceModel = model;
        deviceModel.link.bytesPerBox = static_cast<double>(bpaccel::loadBoxBytes(keyWidth));
        for (const auto kind : {bpaccel::HandOvers::Asynchronous, bpaccel::HandOvers::Polled}) {
          auto run = std::make_unique<Timed::Paced>();
          bpaccel::BroadPhaseConfig pacedConfig = config;
          pacedConfig.handOvers = kind;
          pacedConfig.observer = &run->timing;
          run->phase = std::make_unique<bpaccel::PacedBroadPhase>(*t.recording, *t.backend, deviceModel, pacedConfig);
          t.paced.push_back(std::move(run));
        }
      }
      timed.push_back(std::move(t));
    }

  std::vector<char> flood(evict ? 64u << 20 : 0);
  std::vector<bpaccel::Pair> pairs;
  unsigned sink = 0;
  std::size_t turn = 0;
  for (std::size_t p = 0; p < passes; ++p) {
    for (std::size_t f = 0; f < frames; ++f, ++turn) {
      for (std::size_t k = 0; k < timed.size(); ++k) {
        Timed& t = timed[(k + turn) % timed.size()];
        for (std::size_t b = 0; b < flood.size(); b += 64) sink += static_cast<unsigned char>(++flood[b]);
        t.recording->clear();
        const std::size_t allocationsBefore = gAllocations;
        const auto t0 = Clock::now();
        t.phase->findPairs(recorded[f], pairs);
        const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
        const auto& times = t.timing->times();
        const double hostSeconds = wall - times.backendSeconds;
        t.host.push_back(hostSeconds);
        if (p > 0) t.allocations.push_back(static_cast<double>(gAllocations - allocationsBefore));
        t.convert.push_back(times.convertSeconds);
        t.part.push_back(times.partitionSeconds);
        t.cells.push_back(times.cellsSeconds - times.backendSeconds);
        double decoded = 0;
        for (const auto& r : t.timing->handOvers()) decoded += r.decodeSeconds;
        t.decode.push_back(decoded);
        // The link carries the device's keys.
        model.link.bytesPerBox = static_cast<double>(bpaccel::loadBoxBytes(t.keyWidth));
        t.pipelined.push_back(bpaccel::modelPipeline(t.timing->handOvers(), hostSeconds, model).frameSeconds);
        bpaccel::PipelineModel polled = model;
        polled.decodeOnProducer = true;
        const auto polledTimeline = bpaccel::modelPipeline(t.timing->handOvers(), hostSeconds, polled);
        t.pipelinedPolled.push_back(polledTimeline.frameSeconds);
        t.modelledSpans.emplace_back();
        for (const auto& span : polledTimeline.device) t.modelledSpans.back().emplace_back(span.start, span.end);
        t.lastReady.push_back(t.timing->handOvers().empty() ? 0 : t.timing->handOvers().back().readySeconds);
        std::sort(pairs.begin(), pairs.end());
        if (pairs != exact[f]) {
          fmt::print(stderr, "frame_timing: frame {} pass {}: {} pairs, the exact set has {}\n", f, p, pairs.size(),
                     exact[f].size());
          return 1;
        }
        for (std::size_t q = 0; q < t.paced.size(); ++q) {  // the kinds in a rotating order too
          Timed::Paced& run = *t.paced[(q + turn) % t.paced.size()];
          for (std::size_t b = 0; b < flood.size(); b += 64) sink += static_cast<unsigned char>(++flood[b]);
          run.phase->awakenDevice();  // as the bench does: the emulated device, like a card, needs no waking
          const auto p0 = Clock::now();
          run.phase->findPairs(recorded[f], pairs);
          run.wall.push_back(std::chrono::duration<double>(Clock::now() - p0).count());
          // When the producer handed its last batch over (waits for room left out).
          const bpaccel::LastFrameTiming& timing = run.timing;
          run.lastReady.push_back(timing.handOvers().back().readySeconds);
          run.waits.push_back(timing.times().backendSeconds);
          double decoding = 0;
          for (const auto& r : timing.handOvers()) decoding += r.decodeSeconds;
          run.decode.push_back(decoding);
          std::sort(pairs.begin(), pairs.end());
          if (pairs != exact[f]) {
            fmt::print(stderr, "frame_timing: paced frame {} pass {}: {} pairs, the exact set has {}\n", f, p,
                       pairs.size(), exact[f].size());
            return 1;
          }
        }
      }
    }
  }
  const auto us = [](const std::vector<double>& v) { return median(v) * 1e6; };
  fmt::print("objects {} partition {} cell {} cells/batch {} backend {} frames {} evict {} (sink {})\n", objects,
             partition, cellSize, cellsPerBatch, timed.front().backend->name(), timed.front().host.size(), evict,
             sink & 1);
  for (std::size_t k = 0; k < timed.size(); ++k) {
    const Timed& t = timed[k];
    const auto& stats = t.phase->stats();
    fmt::print("key_width {} first_batch_cells {} host_us {:.1f} convert_us {:.1f} partition_us {:.1f} "
               "cells_host_us {:.1f} (decode_us {:.1f}) pipelined_us_modelled {:.1f} (producer decoding: {:.1f}) "
               "at {} MHz; pairs {} hits {} runs {} batches {} device_cycles {} allocations/frame {}\n",
               t.keyWidth, t.phase->config().firstBatch(), us(t.host), us(t.convert), us(t.part), us(t.cells), us(t.decode),
               us(t.pipelined), us(t.pipelinedPolled), clockMHz, pairs.size(), stats.hits, stats.runs, stats.batches,
               stats.deviceCycles(), median(t.allocations));
    for (const auto& run : t.paced) {
      const bool polled = run->phase->phase().config().handOvers == bpaccel::HandOvers::Polled;
      const std::string kind = polled ? "paced, polled" : "paced, decoder thread";
      const auto& modelled = polled ? t.pipelinedPolled : t.pipelined;
      const auto& late = run->phase->device().lateSeconds();
      std::vector<double> ratio;
      for (std::size_t i = 0; i < run->wall.size(); ++i) ratio.push_back(run->wall[i] / modelled[i]);
      fmt::print("  {}: asynchronous hand-overs against a device held for its modelled time: frame_us {:.1f} "
                 "(measured wall time; device emulated), per frame {:.3f}x the modelled overlapped frame of this "
                 "kind; the device answered a median {:.1f} us late (max {:.1f}) over {} hand-overs\n",
                 kind, us(run->wall), median(ratio), us(late),
                 late.empty() ? 0.0 : *std::max_element(late.begin(), late.end()) * 1e6, late.size());
      fmt::print("  {}: the producer handed its last batch over at {:.1f} us (its waits left out; {:.1f} us in "
                 "the synchronous run, which decodes in between)\n",
                 kind, us(run->lastReady), us(t.lastReady));
      fmt::print("  {}: the producer waited {:.1f} us a frame for room and for the last answers; decoding took "
                 "{:.1f} us a frame ({})\n",
                 kind, us(run->waits), us(run->decode), polled ? "on the producer" : "on the decoder thread");
      if (!run->phase->device().spans().empty())
        fmt::print("  {}: the device's hand-overs, median us from the frame's start:{}\n", kind,
                   medianSpans(run->phase->device().spans()));
    }
    if (!t.modelledSpans.empty() && !t.modelledSpans.front().empty())
      fmt::print("  MODELLED (producer decoding): the device's hand-overs, median us from the frame's start:{}\n",
                 medianSpans(t.modelledSpans));
    if (k > 0) {  // paired with the first configuration, frame by frame
      std::vector<double> ratio;
      for (std::size_t i = 0; i < t.pipelined.size(); ++i) ratio.push_back(t.pipelined[i] / timed[0].pipelined[i]);
      fmt::print("  overlapped frame against key_width {} first_batch_cells {}: median ratio {:.3f}\n",
                 timed[0].keyWidth, timed[0].phase->config().firstBatch(), median(ratio));
    }
  }
  return 0;
}
