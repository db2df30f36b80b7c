#include "accelerator_method.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel {

double LinkModel::seconds(const RunStats& s, std::size_t bytesPerBeat, double clockHz) const {
  const double boxLink = kBytesPerBox * static_cast<double>(s.boxesSent) / bandwidthBytesPerSecond;
  const double boxPort = static_cast<double>(s.loadCycles) / clockHz;
  const double results = static_cast<double>(bytesPerBeat * s.beatsReceived) / bandwidthBytesPerSecond;
  return static_cast<double>(s.batches) * latencySecondsPerRun + std::max(0.0, boxLink - boxPort) + results;
}

std::string cellName(const std::optional<std::size_t>& c) { return c ? std::to_string(*c) : "none"; }

AcceleratorMethod::AcceleratorMethod(std::shared_ptr<const DeviceConfig> device, std::optional<std::size_t> cellSize)
    : device_(std::move(device)), backend_(device_->makeBackend()), phase_(*backend_, cellSize, device_->cellsPerBatch) {}

FrameTime AcceleratorMethod::frameTime(double measuredSeconds) const {
  ModelledParts p;
  p.stats = phase_.stats();
  p.hostSeconds = measuredSeconds - phase_.times().backendSeconds;  // simulating the device is not host work
  p.deviceSeconds = static_cast<double>(p.stats.deviceCycles()) / device_->clockHz;
  p.transferSeconds = device_->link.seconds(p.stats, device_->beatBytes, device_->clockHz);
  const PipelineModel model{device_->clockHz, device_->link.bandwidthBytesPerSecond, device_->link.latencySecondsPerRun,
                            LinkModel::kBytesPerBox, static_cast<double>(device_->beatBytes)};
  p.pipeline = std::make_shared<const FrameTimeline>(modelPipeline(phase_.runs(), p.hostSeconds, model));
  return {p.hostSeconds + p.deviceSeconds + p.transferSeconds, p};
}

namespace {

// One method per cell size; without a tree a method tests all pairs.
std::vector<MethodSpec> perCellSize(const std::string& prefix, MethodKind kind,
                                    const std::vector<std::optional<std::size_t>>& cellSizes, double maxAllPairsTests,
                                    const std::function<std::unique_ptr<TimedMethod>(std::optional<std::size_t>)>& make) {
  std::vector<MethodSpec> specs;
  for (const auto& c : cellSizes) {
    MethodSpec s;
    s.name = prefix + " k-d " + cellName(c);
    s.kind = kind;
    s.library = "bpaccel";
    s.cellSize = c;
    if (!c) s.skipReason = allPairsSkipReason(maxAllPairsTests);
    s.make = [make, c](const SceneStart&) { return make(c); };
    specs.push_back(std::move(s));
  }
  return specs;
}

}  // namespace

std::vector<MethodSpec> acceleratorMethods(std::shared_ptr<const DeviceConfig> device,
                                           const std::vector<std::optional<std::size_t>>& cellSizes,
                                           double maxAllPairsTests) {
  if (!device || !device->makeBackend) throw std::invalid_argument("bench: the accelerator needs a device backend");
  if (!(device->clockHz > 0)) throw std::invalid_argument("bench: clock must be positive");
  return perCellSize("accelerator", MethodKind::Accelerator, cellSizes, maxAllPairsTests,
                     [device](std::optional<std::size_t> c) { return std::make_unique<AcceleratorMethod>(device, c); });
}

std::vector<MethodSpec> threadedCpuMethods(const std::vector<std::optional<std::size_t>>& cellSizes, std::size_t threads) {
  std::vector<MethodSpec> specs;
  for (const auto& c : cellSizes) {
    if (!c) continue;  // one cell: nothing to share out
    MethodSpec s;
    s.name = fmt::format("cpu k-d {}, {} threads", *c, threads);
    s.kind = MethodKind::Cpu;
    s.library = "bpaccel";
    s.cellSize = c;
    s.make = [c, threads](const SceneStart&) { return std::make_unique<CpuMethod>(c, threads); };
    specs.push_back(std::move(s));
  }
  return specs;
}

std::vector<MethodSpec> cpuMethods(const std::vector<std::optional<std::size_t>>& cellSizes, double maxAllPairsTests) {
  return perCellSize("cpu", MethodKind::Cpu, cellSizes, maxAllPairsTests,
                     [](std::optional<std::size_t> c) { return std::make_unique<CpuMethod>(c); });
}

}  // namespace bpaccel
