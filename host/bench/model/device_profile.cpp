#include "device_profile.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>

#include "fpga_report.hpp"

namespace bpaccel {

namespace {

nlohmann::json valueJson(const ProfiledValue& v) {
  return {{"value", v.value}, {"provenance", provenanceName(v.provenance)}, {"source", v.source}};
}

// The LFE5U-85F speed 6 clock of the built device, which profiles without a
// report of their own run on: a stand-in where measured, else the default.
ProfiledValue lfe5uStandIn(const ProfileInputs& in) {
  const DeviceClock c = clockFromFpgaReport(in.lfe5uReport, in.device.m, in.device.arch, in.device.keyWidth);
  if (c.measured) return {c.hz, Provenance::StandIn, "stand-in: LFE5U-85F speed 6 clock, " + c.source};
  return {c.hz, Provenance::Assumed, "assumed: " + c.source};
}

LinkProfile pcieLink(std::string generation, unsigned lanes, double gtPerSecond, int payloadBits, int lineBits,
                     ProfiledValue effective, ProfiledValue latency) {
  LinkProfile l;
  l.generation = std::move(generation);
  l.lanes = lanes;
  l.gigaTransfersPerSecond = gtPerSecond;
  l.encoding = fmt::format("{}b/{}b", payloadBits, lineBits);
  l.rawBytesPerSecond = {rawLinkBytesPerSecond(lanes, gtPerSecond, payloadBits, lineBits), Provenance::Specified,
                         fmt::format("{} x{}: {} GT/s a lane, {} encoding", l.generation, lanes, gtPerSecond, l.encoding)};
  l.effectiveBytesPerSecond = std::move(effective);
  l.latencySeconds = std::move(latency);
  return l;
}

// A hand-over's latency on a PCIe card with a DMA engine: nobody measured it for these cards.
ProfiledValue assumedPcieLatency() {
  return {1e-6, Provenance::Assumed, "assumed: about 1 us for a doorbell write to reach the device, or a completion "
                                     "the host (PCIe DMA order of magnitude, not measured)"};
}

}  // namespace

const char* provenanceName(Provenance p) {
  switch (p) {
    case Provenance::Measured: return "measured";
    case Provenance::Specified: return "specified";
    case Provenance::Assumed: return "assumed";
    case Provenance::StandIn: return "stand-in";
  }
  return "?";
}

double rawLinkBytesPerSecond(unsigned lanes, double gigaTransfersPerSecond, int payloadBits, int lineBits) {
  if (lanes == 0 || !(gigaTransfersPerSecond > 0) || payloadBits <= 0 || lineBits < payloadBits)
    throw std::invalid_argument("link: lanes and line rate must be positive, the encoding payload at most its line bits");
  return lanes * gigaTransfersPerSecond * 1e9 * payloadBits / lineBits / 8;
}

LinkModel DeviceProfile::linkModel(double bytesPerBox, double bytesPerBeat) const {
  return {.bandwidthBytesPerSecond = link.effectiveBytesPerSecond.value,
          .latencySeconds = link.latencySeconds.value,
          .bytesPerBox = bytesPerBox,
          .bytesPerBeat = bytesPerBeat};
}

nlohmann::json DeviceProfile::toJson() const {
  return {{"name", name},
          {"description", description},
          {"summary", summary()},
          {"part",
           {{"name", part.name},
            {"speed_grade", part.speedGrade ? nlohmann::json(part.speedGrade) : nlohmann::json(nullptr)},
            {"report", part.report},
            {"report_present", part.reportPresent},
            {"clock_hz", valueJson(part.clockHz)}}},
          {"link",
           {{"generation", link.generation},
            {"lanes", link.lanes},
            {"giga_transfers_per_second_per_lane", link.gigaTransfersPerSecond},
            {"encoding", link.encoding},
            {"raw_bytes_per_second_each_way", valueJson(link.rawBytesPerSecond)},
            {"effective_bytes_per_second_each_way", valueJson(link.effectiveBytesPerSecond)},
            {"latency_seconds_per_transfer", valueJson(link.latencySeconds)}}}};
}

std::string DeviceProfile::summary() const {
  const std::string grade = part.speedGrade ? fmt::format(" speed {}", part.speedGrade) : "";
  const std::string lanes = link.lanes ? fmt::format(" x{}", link.lanes) : "";
  return fmt::format("{}: {}{}, {:.1f} MHz ({}); {}{}, {:.2f} GB/s each way ({}), {:.1f} us a transfer ({})", name,
                     part.name, grade, part.clockHz.value / 1e6, provenanceName(part.clockHz.provenance),
                     link.generation, lanes, link.effectiveBytesPerSecond.value / 1e9,
                     provenanceName(link.effectiveBytesPerSecond.provenance), link.latencySeconds.value * 1e6,
                     provenanceName(link.latencySeconds.provenance));
}

PartProfile resolvePart(std::string name, int speedGrade, std::string report, const BuiltDevice& device,
                        const ProfiledValue& standIn) {
  PartProfile p;
  p.name = std::move(name);
  p.speedGrade = speedGrade;
  p.report = std::move(report);
  p.reportPresent = !p.report.empty() && std::filesystem::is_regular_file(p.report);
  std::string why = fmt::format("no {} report", p.name);
  if (!p.report.empty()) why += ": " + p.report;
  if (p.reportPresent) {
    const DeviceClock c = clockFromFpgaReport(p.report, device.m, device.arch, device.keyWidth);
    if (c.measured) {
      p.clockHz = {c.hz, Provenance::Measured, c.source};
      return p;
    }
    why = fmt::format("{} report not usable: {}", p.name, c.source);
  }
  p.clockHz = standIn;
  p.clockHz.source = why + "; " + standIn.source;
  return p;
}

std::string findFiveGReport(const ProfileInputs& in) {
  const std::string design =
      std::filesystem::path(fpgaReportPath(in.device.m, in.device.arch, in.device.keyWidth)).stem().string();
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& f : std::filesystem::directory_iterator(in.fpgaDir, ec)) {
    const std::string stem = f.path().stem().string();
    if (f.path().extension() == ".json" && stem.rfind(design + "-", 0) == 0 &&
        stem.find("um5g", design.size()) != std::string::npos)
      found.push_back(f.path().string());
  }
  std::sort(found.begin(), found.end());  // the shortest name first: the flow's own, before variants
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.size() < b.size(); });
  return found.empty() ? std::string() : found.front();
}

std::string fiveGReportOrPattern(const ProfileInputs& in) {
  std::string report = findFiveGReport(in);
  if (report.empty())
    report = fmt::format("{}/{}-*um5g*.json (none found)", in.fpgaDir,
                         std::filesystem::path(fpgaReportPath(in.device.m, in.device.arch, in.device.keyWidth))
                             .stem()
                             .string());
  return report;
}

DeviceProfile ecp5FiveGProfile(const ProfileInputs& in) {
  DeviceProfile p;
  p.name = "ecp5-5g";
  p.description = "an ECP5-5G card: the LFE5UM5G-85F speed 8 with its PCIe Gen2 x1 endpoint";
  p.part = resolvePart("LFE5UM5G-85F", 8, fiveGReportOrPattern(in), in.device, lfe5uStandIn(in));
  // Lattice's PCI Express Endpoint IP Core user guide for ECP5 and ECP5-5G
  // (FPGA-IPUG-02009) offers x1 and x2 endpoints, Gen2 (5 GT/s) on the -5G
  // parts; a documentation search here did not return that guide, so x1 is
  // the conservative choice. Rate and encoding are the PCIe Gen2 standard's.
  p.link = pcieLink("PCIe Gen2", 1, 5.0, 8, 10,
                    {400e6, Provenance::Assumed,
                     "assumed: about 80 % of the 500 MB/s raw rate after TLP and DLLP overhead (128-byte payloads)"},
                    assumedPcieLatency());
  return p;
}

DeviceProfile gen3x8Profile(const ProfileInputs& in) {
  DeviceProfile p;
  p.name = "gen3x8";
  p.description = "a PCIe Gen3 x8-class card: link assumed, the LFE5U-85F's measured clock as a conservative stand-in";
  p.part = resolvePart("Gen3 x8-class FPGA (no part named)", 0, "", in.device, lfe5uStandIn(in));
  p.link = pcieLink("PCIe Gen3", 8, 8.0, 128, 130,
                    {6.5e9, Provenance::Assumed,
                     "assumed: about 83 % of the 7.88 GB/s raw rate after TLP and DLLP overhead"},
                    assumedPcieLatency());
  return p;
}

DeviceProfile customLinkProfile(const ProfileInputs& in, double bytesPerSecond, double latencySeconds) {
  DeviceProfile p;
  p.name = "custom";
  p.description = "the LFE5U-85F speed 6 with a link given on the command line (that part has no transceivers)";
  p.part = resolvePart("LFE5U-85F", 6, in.lfe5uReport, in.device, lfe5uStandIn(in));
  p.link.generation = "link given";
  p.link.lanes = 0;  // not given
  p.link.effectiveBytesPerSecond = {bytesPerSecond, Provenance::Assumed, "assumed: --link-gbytes-per-s"};
  p.link.rawBytesPerSecond = p.link.effectiveBytesPerSecond;
  p.link.latencySeconds = {latencySeconds, Provenance::Assumed, "assumed: --link-latency-us"};
  return p;
}

std::vector<std::string> builtInProfileNames() { return {"ecp5-5g", "gen3x8"}; }

DeviceProfile builtInProfile(const std::string& name, const ProfileInputs& in) {
  if (name == "ecp5-5g") return ecp5FiveGProfile(in);
  if (name == "gen3x8") return gen3x8Profile(in);
  throw std::invalid_argument(fmt::format("unknown device profile '{}' (known: ecp5-5g, gen3x8, custom)", name));
}

}  // namespace bpaccel
