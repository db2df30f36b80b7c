#include "fpga_report.hpp"

#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/binning/binning_params.hpp"

namespace bpaccel {

int defaultKeyWidth(const std::string& arch) {
  return arch == "binning" ? static_cast<int>(BinningParams{}.keyWidth) : 32;
}

std::string fpgaReportPath(int m, const std::string& arch, int keyWidth) {
  return fmt::format("results/fpga/{}m{}{}.json", arch == "seed" ? "" : arch + "-", m,
                     keyWidth == defaultKeyWidth(arch) ? "" : fmt::format("-k{}", keyWidth));
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
      return {mhz * 1e6, fmt::format("Fmax {:.2f} MHz measured by nextpnr on ECP5 ({}{})", mhz, fpgaReport, run), true};
    return fallback(fpgaReport + " has no positive Fmax");
  } catch (const std::exception& e) {
    return fallback(fmt::format("{} unreadable: {}", fpgaReport, e.what()));
  }
}

}  // namespace bpaccel
