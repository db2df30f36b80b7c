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
// --paced also runs each configuration's asynchronous hand-overs
// (HandOvers::Asynchronous: the producer, the device's thread and the decoder
// thread) against a device held for its modelled time (PacedDevice), and
// prints that frame's measured wall time beside the modelled overlapped
// frame: a check of the model against the threads that run it. The paced
// device replays the model backend's answers recorded in the synchronous
// run of the same frame; only its duration is emulated.
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
#include <thread>
#include <vector>

#include <sys/prctl.h>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "async_backend.hpp"
#include "backend.hpp"
#include "broad_phase.hpp"
#include "exact_pairs.hpp"
#include "rtl_backend.hpp"
#include "scene.hpp"
#include "timeline.hpp"

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

// Each hand-over's answer, recorded from the synchronous run of a frame and
// replayed in the same order by the paced run of the same frame (the
// asynchronous hand-overs are the synchronous ones: the tests prove it).
using Recording = std::vector<bpaccel::BatchResult>;

// Appends one hand-over's own answer to what Backend::runBatch fills.
void append(const bpaccel::BatchResult& answer, std::vector<bpaccel::Pair>& out, std::vector<std::size_t>& cellEnds,
            bpaccel::RunStats& stats) {
  const std::size_t base = out.size();
  out.insert(out.end(), answer.pairs.begin(), answer.pairs.end());
  for (const std::size_t end : answer.cellEnds) cellEnds.push_back(base + end);
  stats += answer.stats;
}

// The synchronous run's device: the model backend, its answers recorded.
class RecordingDevice final : public bpaccel::Backend {
 public:
  RecordingDevice(std::unique_ptr<bpaccel::Backend> inner, Recording& recording)
      : inner_(std::move(inner)), recording_(recording) {}
  std::string name() const override { return inner_->name(); }
  std::size_t capacity() const override { return inner_->capacity(); }
  unsigned keyWidth() const override { return inner_->keyWidth(); }
  bool bipartite() const override { return inner_->bipartite(); }
  void run(std::span<const bpaccel::KeyBox>, std::vector<bpaccel::Pair>&, bpaccel::RunStats&) override {
    throw std::logic_error("frame_timing: the recorded device takes batches only");
  }
  void runBatch(std::span<const std::span<const bpaccel::KeyBox>> cells, std::span<const std::size_t> splits,
                std::vector<bpaccel::Pair>& out, std::vector<std::size_t>& cellEnds,
                bpaccel::RunStats& stats) override {
    bpaccel::BatchResult r;  // this hand-over's own: its cell ends count from 0
    inner_->runBatch(cells, splits, r.pairs, r.cellEnds, r.stats);
    append(r, out, cellEnds, stats);
    recording_.push_back(std::move(r));
  }

 private:
  std::unique_ptr<bpaccel::Backend> inner_;
  Recording& recording_;
};

// A device that takes its modelled time and no more: it answers each
// hand-over with the recorded answer (so simulating the device costs this
// thread nothing: the model backend's own all-pairs work would take longer
// than the device it models) once a command's latency, the load, the run
// (or the results on the link, if longer) and a completion's latency have
// passed since the hand-over reached it (handOverTimes, the model's own
// parts). It holds the device through the completion's latency, which the
// model overlaps with the next hand-over: 1 us a hand-over more than the model.
class PacedDevice final : public bpaccel::Backend {
 public:
  /// `recorded`: the device whose answers `recording` holds (its capacity, key width and runs are this one's).
  PacedDevice(const Recording& recording, const bpaccel::Backend& recorded, const bpaccel::PipelineModel& model)
      : recording_(recording), recorded_(recorded), model_(model) {
    prctl(PR_SET_TIMERSLACK, 1UL);  // this thread's sleeps end on time, not up to 50 us late
  }
  std::string name() const override { return "paced replay"; }
  std::size_t capacity() const override { return recorded_.capacity(); }
  unsigned keyWidth() const override { return recorded_.keyWidth(); }
  bool bipartite() const override { return recorded_.bipartite(); }
  void run(std::span<const bpaccel::KeyBox>, std::vector<bpaccel::Pair>&, bpaccel::RunStats&) override {
    throw std::logic_error("frame_timing: the paced device takes batches only");
  }
  /// Called before each frame: its hand-overs replay the recording from the start.
  void rewind(Clock::time_point frameStart) {
    next_ = 0;
    frameStart_ = frameStart;
  }
  // Read once a frame has ended. Per hand-over of each frame so far: when it
  // reached the device and when the device answered (s from the frame's
  // start); and how late it answered, all frames together.
  std::vector<std::vector<std::pair<double, double>>> spans;
  std::vector<double> lateSeconds;
  void runBatch(std::span<const std::span<const bpaccel::KeyBox>> cells, std::span<const std::size_t>,
                std::vector<bpaccel::Pair>& out, std::vector<std::size_t>& cellEnds,
                bpaccel::RunStats& stats) override {
    const auto reached = Clock::now();
    if (next_ >= recording_.size() || recording_[next_].cellEnds.size() != cells.size())
      throw std::logic_error("frame_timing: the paced run's hand-overs differ from the recorded ones");
    const bpaccel::BatchResult& r = recording_[next_++];
    append(r, out, cellEnds, stats);
    const auto t = bpaccel::handOverTimes(r.stats, model_);
    const double hold = 2 * model_.latencySeconds + t.loadSeconds + std::max(t.computeSeconds, t.resultsSeconds);
    const auto until = reached + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(hold));
    // A sleep ends about 15-20 us late here: sleep to near the end, then spin.
    std::this_thread::sleep_until(until - std::chrono::microseconds(kSpinMicroseconds));
    while (Clock::now() < until) {
    }
    const auto answered = Clock::now();
    lateSeconds.push_back(std::chrono::duration<double>(answered - until).count());
    if (next_ == 1) spans.emplace_back();
    spans.back().emplace_back(std::chrono::duration<double>(reached - frameStart_).count(),
                              std::chrono::duration<double>(answered - frameStart_).count());
  }

 private:
  static constexpr int kSpinMicroseconds = 30;
  const Recording& recording_;
  const bpaccel::Backend& recorded_;
  bpaccel::PipelineModel model_;
  std::size_t next_ = 0;
  Clock::time_point frameStart_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Host work per frame of the accelerator method, by part, on the benchmark's scene"};
  std::size_t objects = 8000, cellSize = 128, cellsPerBatch = 16, frames = 30, passes = 10;
  std::string partition = "grid", backendName = "model";
  std::vector<std::size_t> firstBatchCells;
  std::vector<unsigned> keyWidths;
  double clockMHz = 100;
  bool evict = false;
  app.add_option("--objects", objects)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--cell-size", cellSize)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--partition", partition)->capture_default_str()->check(CLI::IsMember({"kd", "grid"}));
  app.add_option("--cells-per-batch", cellsPerBatch)->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--first-batch-cells", firstBatchCells,
                 "Cells of each frame's first hand-over (BroadPhase::setFirstBatchCells); several: compared")
      ->check(CLI::PositiveNumber);
  app.add_option("--clock-mhz", clockMHz, "Device clock of the modelled overlapped frame")->capture_default_str()
      ->check(CLI::PositiveNumber);
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
  const unsigned builtKeyWidth = bpaccel::modelOfBuiltHardware().keyWidth();
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
    return std::make_unique<bpaccel::ModelBackend>(bpaccel::modelOfBuiltHardware(keyWidth));
  };
  // One configuration: its backend, its broad phase and its figures.
  struct Timed {
    std::unique_ptr<bpaccel::Backend> backend;
    std::unique_ptr<bpaccel::BroadPhase> phase;
    std::vector<double> host, convert, part, cells, decode, pipelined;
    std::vector<double> allocations;  // after the first pass
    unsigned keyWidth = 32;
    // --paced: the same configuration's asynchronous hand-overs on a paced device.
    std::unique_ptr<bpaccel::BroadPhase> pacedPhase;
    std::unique_ptr<Recording> recording = std::make_unique<Recording>();  // the synchronous run's answers
    PacedDevice* pacedDevice = nullptr;  // owned by pacedPhase's device thread
    std::vector<double> pacedWall, pacedLastReady, lastReady, pacedWaits, pacedDecode;
  };
  bpaccel::PipelineModel model;  // the benchmark's link model (--link-gbytes-per-s 4, --link-latency-us 1)
  model.clockHz = clockMHz * 1e6;
  model.bytesPerBeat = static_cast<double>(bpaccel::resultBeatBytesOfBuiltHardware());
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
      if (paced) t.backend = std::make_unique<RecordingDevice>(std::move(t.backend), *t.recording);
      t.phase = std::make_unique<bpaccel::BroadPhase>(*t.backend, cellSize, cellsPerBatch,
                                                      bpaccel::parsePartitionKind(partition));
      t.phase->setFirstBatchCells(first);
      if (paced) {
        bpaccel::PipelineModel deviceModel = model;
        deviceModel.bytesPerBox = static_cast<double>(bpaccel::loadBoxBytes(keyWidth));
        // Built on the device's thread while the constructor waits: the pointer is set when it returns.
        t.pacedPhase = std::make_unique<bpaccel::BroadPhase>(
            [&t, deviceModel] {
              auto device = std::make_unique<PacedDevice>(*t.recording, *t.backend, deviceModel);
              t.pacedDevice = device.get();
              return device;
            },
            cellSize, 1, cellsPerBatch, bpaccel::parsePartitionKind(partition), bpaccel::HandOvers::Asynchronous);
        t.pacedPhase->setFirstBatchCells(first);
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
        const auto& times = t.phase->times();
        const double hostSeconds = wall - times.backendSeconds;
        t.host.push_back(hostSeconds);
        if (p > 0) t.allocations.push_back(static_cast<double>(gAllocations - allocationsBefore));
        t.convert.push_back(times.convertSeconds);
        t.part.push_back(times.partitionSeconds);
        t.cells.push_back(times.cellsSeconds - times.backendSeconds);
        double decoded = 0;
        for (const auto& r : t.phase->runs()) decoded += r.decodeSeconds;
        t.decode.push_back(decoded);
        // The link carries the device's keys.
        model.bytesPerBox = static_cast<double>(bpaccel::loadBoxBytes(t.keyWidth));
        t.pipelined.push_back(bpaccel::modelPipeline(t.phase->runs(), hostSeconds, model).frameSeconds);
        std::sort(pairs.begin(), pairs.end());
        if (pairs != exact[f]) {
          fmt::print(stderr, "frame_timing: frame {} pass {}: {} pairs, the exact set has {}\n", f, p, pairs.size(),
                     exact[f].size());
          return 1;
        }
        if (t.pacedPhase) {
          for (std::size_t b = 0; b < flood.size(); b += 64) sink += static_cast<unsigned char>(++flood[b]);
          const auto p0 = Clock::now();
          t.pacedDevice->rewind(p0);
          t.pacedPhase->findPairs(recorded[f], pairs);
          t.pacedWall.push_back(std::chrono::duration<double>(Clock::now() - p0).count());
          // When the producer handed its last batch over, in both runs (waits for room left out).
          t.pacedLastReady.push_back(t.pacedPhase->runs().back().readySeconds);
          t.lastReady.push_back(t.phase->runs().back().readySeconds);
          t.pacedWaits.push_back(t.pacedPhase->times().backendSeconds);
          double decoding = 0;
          for (const auto& r : t.pacedPhase->runs()) decoding += r.decodeSeconds;
          t.pacedDecode.push_back(decoding);
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
               "cells_host_us {:.1f} (decode_us {:.1f}) pipelined_us_modelled {:.1f} at {} MHz; pairs {} hits {} "
               "runs {} batches {} device_cycles {} allocations/frame {}\n",
               t.keyWidth, t.phase->firstBatchCells(), us(t.host), us(t.convert), us(t.part), us(t.cells), us(t.decode),
               us(t.pipelined), clockMHz, pairs.size(), stats.hits, stats.runs, stats.batches, stats.deviceCycles(),
               median(t.allocations));
    if (t.pacedPhase) {
      const auto& late = t.pacedDevice->lateSeconds;
      std::vector<double> ratio;
      for (std::size_t i = 0; i < t.pacedWall.size(); ++i) ratio.push_back(t.pacedWall[i] / t.pipelined[i]);
      fmt::print("  paced: asynchronous hand-overs against a device held for its modelled time: frame_us {:.1f} "
                 "(measured wall time; device emulated), per frame {:.3f}x the modelled overlapped frame; "
                 "the device answered a median {:.1f} us late (max {:.1f}) over {} hand-overs\n",
                 us(t.pacedWall), median(ratio), us(late),
                 late.empty() ? 0.0 : *std::max_element(late.begin(), late.end()) * 1e6, late.size());
      fmt::print("  paced: the producer handed its last batch over at {:.1f} us (its waits left out; {:.1f} us in "
                 "the synchronous run, which decodes in between)\n",
                 us(t.pacedLastReady), us(t.lastReady));
      fmt::print("  paced: the producer waited {:.1f} us a frame for room and for the last decode; the decoder "
                 "thread decoded for {:.1f} us a frame\n",
                 us(t.pacedWaits), us(t.pacedDecode));
    }
    if (t.pacedPhase && !t.pacedDevice->spans.empty()) {  // hand-over h's median span over the frames
      const auto& spans = t.pacedDevice->spans;
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
      fmt::print("  paced: the device's hand-overs, median us from the frame's start:{}\n", line);
    }
    if (k > 0) {  // paired with the first configuration, frame by frame
      std::vector<double> ratio;
      for (std::size_t i = 0; i < t.pipelined.size(); ++i) ratio.push_back(t.pipelined[i] / timed[0].pipelined[i]);
      fmt::print("  overlapped frame against key_width {} first_batch_cells {}: median ratio {:.3f}\n",
                 timed[0].keyWidth, timed[0].phase->firstBatchCells(), median(ratio));
    }
  }
  return 0;
}
