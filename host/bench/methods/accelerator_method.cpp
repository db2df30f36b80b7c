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

std::vector<MethodSpec> acceleratorMethods(std::shared_ptr<const DeviceConfig> device,
                                           const std::vector<std::optional<std::size_t>>& cellSizes,
                                           double maxAllPairsTests, PartitionKind partition) {
  if (!device || !device->makeBackend) throw std::invalid_argument("bench: the accelerator needs a device backend");
  if (!(device->clockHz > 0)) throw std::invalid_argument("bench: clock must be positive");
  return perCellSize("accelerator", MethodKind::Accelerator, partition, cellSizes, maxAllPairsTests,
                     [device, partition](std::optional<std::size_t> c) {
                       return std::make_unique<AcceleratorMethod>(device, c, partition);
                     });
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

std::string fpgaReportPath(int m, const std::string& arch, int keyWidth) {
  return fmt::format("results/fpga/{}m{}{}.json", arch == "seed" ? "" : arch + "-", m,
                     keyWidth == 32 ? "" : fmt::format("-k{}", keyWidth));
}

DeviceClock clockFromFpgaReport(const std::string& fpgaReport, int m, const std::string& arch, int keyWidth) {
  const auto fallback = [](std::string why) { return DeviceClock{100e6, "default 100 MHz (" + std::move(why) + ")"}; };
  std::ifstream in(fpgaReport);
  if (!in) return fallback("no FPGA report at " + fpgaReport);
  try {
    const auto j = nlohmann::json::parse(in);
    if (j.at("status") != "ok" || !j.at("result_valid").get<bool>())
      return fallback(fpgaReport + " holds no valid result");
    if (const int reportM = j.at("m").get<int>(); reportM != m)
      return fallback(fmt::format("{} is for m = {}, not {}", fpgaReport, reportM, m));
    if (const auto reportArch = j.value("arch", std::string("seed")); reportArch != arch)
      return fallback(fmt::format("{} is for arch = {}, not {}", fpgaReport, reportArch, arch));
    if (const int reportKeys = j.value("key_width", 32); reportKeys != keyWidth)
      return fallback(fmt::format("{} is for {}-bit keys, not {}", fpgaReport, reportKeys, keyWidth));
    const double mhz = j.at("ecp5").at("fmax_mhz").get<double>();
    // Which design and placement it measured, where the report says (older ones do not).
    std::string run;
    if (const auto rev = j.find("source_revision"); rev != j.end() && rev->is_string())
      run += fmt::format(", revision {}", rev->get<std::string>());
    if (const auto seed = j.find("nextpnr_seed"); seed != j.end() && seed->is_number_integer())
      run += fmt::format(", placer seed {}", seed->get<int>());
    if (mhz > 0)
      return {mhz * 1e6, fmt::format("Fmax {:.2f} MHz measured by nextpnr on ECP5 ({}{})", mhz, fpgaReport, run)};
    return fallback(fpgaReport + " has no positive Fmax");
  } catch (const std::exception& e) {
    return fallback(fmt::format("{} unreadable: {}", fpgaReport, e.what()));
  }
}

}  // namespace bpaccel
