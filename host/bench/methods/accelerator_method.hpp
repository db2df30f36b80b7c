#pragma once
// The project's own broad phase as benchmark methods: the accelerator (device
// modelled from its cycle counters, host measured) and the cpu backend.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "device/cpu_backend.hpp"
#include "device/backend.hpp"
#include "broad_phase/broad_phase.hpp"
#include "model/device_profile.hpp"
#include "model/fpga_report.hpp"
#include "model/paced_backend.hpp"
#include "timed_method.hpp"

namespace bpaccel {

/// The device the accelerator methods model, given at run time by the program
/// that links a hardware configuration (the benchmark library links none).
struct DeviceConfig {
  std::string backend = "model";                      // where device cycles come from: rtl or model
  std::function<std::unique_ptr<Backend>()> makeBackend;
  nlohmann::json hardware;                            // m, capacity, ... as the JSON reports them
  double clockHz = 100e6;
  std::string clockSource = "default 100 MHz";
  LinkModel link;                                     // with the device's bytes a box and a result beat
  /// The platform the clock and link come from (withProfile); none: set by hand, as tests do.
  std::optional<DeviceProfile> profile;
  /// Cells per hand-over to the device (the hardware's batch front end);
  /// 1 hands each cell over on its own, as before batches existed.
  std::size_t cellsPerBatch = 1;
  /// Cells of a frame's first hand-over, doubling up to cellsPerBatch
  /// (BroadPhaseConfig::firstBatchCells); 0: every hand-over holds cellsPerBatch.
  std::size_t firstBatchCells = 0;
  /// Each frame also runs paced (TimedMethod::runPaced): the host's polled
  /// asynchronous hand-overs (HandOvers::Polled) against a PacedBackend that
  /// replays the frame's recorded answers in their modelled time. Needs
  /// cellsPerBatch of at least 2.
  bool paced = false;
};

/// `device` on `profile`'s part and link: its clock, link rates and latency
/// from the profile, its bytes a box and a result beat its own.
DeviceConfig withProfile(const DeviceConfig& device, const DeviceProfile& profile);

/// BroadPhase on the device: host part measured, device and link modelled.
/// With DeviceConfig::paced, the device's answers are recorded in update()
/// (RecordingBackend) and runPaced() runs the frame again on a second broad
/// phase with polled asynchronous hand-overs, against a PacedBackend.
class AcceleratorMethod final : public TimedMethod {
 public:
  AcceleratorMethod(std::shared_ptr<const DeviceConfig> device, std::optional<std::size_t> cellSize,
                    PartitionKind partition = PartitionKind::KdTree);
  void update(std::span<const Aabb> boxes) override;
  void pairs(std::vector<Pair>& out) override { out = pairs_; }
  /// Host = measured wall time minus the time spent simulating the device;
  /// device = every busy cycle (loads included) / clock; transfer = transferSeconds.
  FrameTime frameTime(double measuredSeconds) const override;
  bool hasPacedRun() const override { return pacedPhase_ != nullptr; }
  void readyPacedDevice() override {
    if (pacedPhase_) pacedPhase_->awakenDevice();
  }
  void runPaced(std::span<const Aabb> boxes) override;

 private:
  PipelineModel pipelineModel() const;
  std::shared_ptr<const DeviceConfig> device_;
  std::unique_ptr<AnswerRecording> recording_;  // with paced runs: the last update's answers
  std::unique_ptr<Backend> backend_;
  LastFrameTiming timing_;  // each update's, for the frame's parts and its pipeline
  BroadPhase phase_;
  // After the recording and the recorded backend, which its device thread reads: it goes first.
  std::unique_ptr<PacedBroadPhase> pacedPhase_;
  std::vector<Pair> pairs_;
};

/// BroadPhase on the cpu backend: software alone, all measured. With several
/// threads the tree is built on one and its cells shared out among them.
class CpuMethod final : public TimedMethod {
 public:
  explicit CpuMethod(CellSize cellSize, std::size_t threads = 1, PartitionKind partition = PartitionKind::KdTree)
      : phase_([] { return std::make_unique<CpuBackend>(); },
               {.cellSize = cellSize, .partition = partition, .threads = threads}) {}
  void update(std::span<const Aabb> boxes) override { phase_.findPairs(boxes, pairs_); }
  void pairs(std::vector<Pair>& out) override { out = pairs_; }

 private:
  BroadPhase phase_;
  std::vector<Pair> pairs_;
};

/// "accelerator k-d C" per cell size (none = no tree, all pairs: skipped above `maxAllPairsTests`);
/// with the grid partition "accelerator grid C" (none = the same all pairs as k-d none: left out).
/// A device with a profile names it: "accelerator k-d C on <profile>", and its specs carry the profile.
std::vector<MethodSpec> acceleratorMethods(std::shared_ptr<const DeviceConfig> device,
                                           const std::vector<std::optional<std::size_t>>& cellSizes,
                                           double maxAllPairsTests, PartitionKind partition = PartitionKind::KdTree);
/// "cpu k-d C" (or "cpu grid C") per cell size, with the same rules.
std::vector<MethodSpec> cpuMethods(const std::vector<std::optional<std::size_t>>& cellSizes, double maxAllPairsTests,
                                   PartitionKind partition = PartitionKind::KdTree);
/// "cpu k-d C, T threads" per cell size with a tree.
std::vector<MethodSpec> threadedCpuMethods(const std::vector<std::optional<std::size_t>>& cellSizes, std::size_t threads);
/// "cpu auto" (the broad phase's own choice of partition and cell size) and,
/// with `threads` above 1, "cpu auto, T threads".
std::vector<MethodSpec> automaticCpuMethods(std::size_t threads);

}  // namespace bpaccel
