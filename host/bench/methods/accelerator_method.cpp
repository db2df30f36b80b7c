#include "accelerator_method.hpp"

#include <algorithm>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

namespace {

// The device's backend, recording its answers when the method runs paced.
std::unique_ptr<Backend> recordedBackend(const DeviceConfig& device, AnswerRecording* recording) {
  auto backend = device.makeBackend();
  if (!backend) throw std::invalid_argument("accelerator method: the device config gave no backend");
  if (!recording) return backend;
  return std::make_unique<RecordingBackend>(std::move(backend), *recording);
}

}  // namespace

AcceleratorMethod::AcceleratorMethod(std::shared_ptr<const DeviceConfig> device, std::optional<std::size_t> cellSize,
                                     PartitionKind partition)
    : device_(std::move(device)),
      recording_(device_->paced ? std::make_unique<AnswerRecording>() : nullptr),
      backend_(recordedBackend(*device_, recording_.get())),
      phase_(*backend_, {.cellSize = cellSize,
                         .partition = partition,
                         .cellsPerBatch = device_->cellsPerBatch,
                         .firstBatchCells = device_->firstBatchCells,
                         .observer = &timing_}) {
  // Its batches need at least two cells (BroadPhase refuses fewer).
  if (device_->paced) {
    BroadPhaseConfig paced = phase_.config();
    paced.handOvers = HandOvers::Polled;
    paced.observer = nullptr;  // the paced run is timed as a whole
    pacedPhase_ = std::make_unique<PacedBroadPhase>(*recording_, *backend_, pipelineModel(), paced);
  }
}

void AcceleratorMethod::update(std::span<const Aabb> boxes) {
  if (recording_) recording_->clear();
  phase_.findPairs(boxes, pairs_);
}

PipelineModel AcceleratorMethod::pipelineModel() const {
  PipelineModel model{.clockHz = device_->clockHz, .link = device_->link};
  model.decodeOnProducer = true;  // the schedule runPaced measures: HandOvers::Polled
  return model;
}

FrameTime AcceleratorMethod::frameTime(double measuredSeconds) const {
  ModelledParts p;
  p.stats = phase_.stats();
  p.hostSeconds = measuredSeconds - timing_.times().backendSeconds;  // simulating the device is not host work
  p.partitionSeconds = timing_.times().partitionSeconds;
  p.deviceSeconds = static_cast<double>(p.stats.deviceCycles()) / device_->clockHz;
  p.transferSeconds = transferSeconds(p.stats, device_->link, device_->clockHz);
  p.pipeline = std::make_shared<const FrameTimeline>(modelPipeline(timing_.handOvers(), p.hostSeconds, pipelineModel()));
  return {p.hostSeconds + p.deviceSeconds + p.transferSeconds, p};
}

void AcceleratorMethod::runPaced(std::span<const Aabb> boxes) {
  if (!pacedPhase_) throw std::logic_error("accelerator method: built without paced runs");
  pacedPhase_->findPairs(boxes, pairs_);
}

namespace {

// One method per cell size; without a cell size a method tests all pairs,
// which only the k-d line-up holds (the grid's "none" would be the same method).
std::vector<MethodSpec> perCellSize(const std::string& prefix, MethodKind kind, PartitionKind partition,
                                    const std::vector<std::optional<std::size_t>>& cellSizes, double maxAllPairsTests,
                                    const std::function<std::unique_ptr<TimedMethod>(std::optional<std::size_t>)>& make) {
  std::vector<MethodSpec> specs;
  for (const auto& c : cellSizes) {
    if (!c && partition != PartitionKind::KdTree) continue;
    MethodSpec s;
    s.name = fmt::format("{} {} {}", prefix, partitionName(partition), cellSizeName(c));
    s.kind = kind;
    s.library = "bpaccel";
    s.cellSize = c;
    s.partition = partitionName(partition);
    if (!c) s.skipReason = allPairsSkipReason(maxAllPairsTests);
    s.make = [make, c](const SceneStart&) { return make(c); };
    specs.push_back(std::move(s));
  }
  return specs;
}

}  // namespace

DeviceConfig withProfile(const DeviceConfig& device, const DeviceProfile& profile) {
  DeviceConfig d = device;
  d.clockHz = profile.part.clockHz.value;
  d.clockSource = fmt::format("{} ({})", profile.part.clockHz.source, profile.part.name);
  d.link = profile.linkModel(device.link.bytesPerBox, device.link.bytesPerBeat);
  d.profile = profile;
  return d;
}

std::vector<MethodSpec> acceleratorMethods(std::shared_ptr<const DeviceConfig> device,
                                           const std::vector<std::optional<std::size_t>>& cellSizes,
                                           double maxAllPairsTests, PartitionKind partition) {
  if (!device || !device->makeBackend) throw std::invalid_argument("bench: the accelerator needs a device backend");
  if (!(device->clockHz > 0)) throw std::invalid_argument("bench: clock must be positive");
  auto specs = perCellSize("accelerator", MethodKind::Accelerator, partition, cellSizes, maxAllPairsTests,
                           [device, partition](std::optional<std::size_t> c) {
                             return std::make_unique<AcceleratorMethod>(device, c, partition);
                           });
  if (device->profile)
    for (auto& s : specs) {
      s.name += " on " + device->profile->name;
      s.profile = device->profile->toJson();
    }
  return specs;
}

std::vector<MethodSpec> threadedCpuMethods(const std::vector<std::optional<std::size_t>>& cellSizes, std::size_t threads) {
  std::vector<MethodSpec> specs;
  for (const auto& c : cellSizes) {
    if (!c) continue;  // one cell: nothing to share out
    MethodSpec s;
    s.name = fmt::format("cpu k-d {}, {} threads", *c, threads);
    s.partition = partitionName(PartitionKind::KdTree);
    s.kind = MethodKind::Cpu;
    s.library = "bpaccel";
    s.cellSize = c;
    s.make = [c, threads](const SceneStart&) { return std::make_unique<CpuMethod>(c, threads); };
    specs.push_back(std::move(s));
  }
  return specs;
}

std::vector<MethodSpec> automaticCpuMethods(std::size_t threads) {
  std::vector<MethodSpec> specs;
  for (std::size_t t : {std::size_t{1}, threads}) {
    if (t < 2 && !specs.empty()) continue;
    MethodSpec s;
    s.name = t == 1 ? "cpu auto" : fmt::format("cpu auto, {} threads", t);
    s.partition = partitionName(PartitionKind::Automatic);
    s.kind = MethodKind::Cpu;
    s.library = "bpaccel";
    s.make = [t](const SceneStart&) {
      return std::make_unique<CpuMethod>(CellSize::automatic(), t, PartitionKind::Automatic);
    };
    specs.push_back(std::move(s));
  }
  return specs;
}

std::vector<MethodSpec> cpuMethods(const std::vector<std::optional<std::size_t>>& cellSizes, double maxAllPairsTests,
                                   PartitionKind partition) {
  return perCellSize("cpu", MethodKind::Cpu, partition, cellSizes, maxAllPairsTests,
                     [partition](std::optional<std::size_t> c) { return std::make_unique<CpuMethod>(c, 1, partition); });
}

}  // namespace bpaccel
