#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "methods/accelerator_method.hpp"
#include "model/device_profile.hpp"
#include "model/link_model.hpp"

using namespace bpaccel;

namespace {

// A folder of FPGA reports for one test, removed after it.
class ReportDir {
 public:
  explicit ReportDir(const std::string& tag)
      : dir_(std::filesystem::temp_directory_path() / (tag + "-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(dir_);
  }
  ~ReportDir() { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, int m, double fmaxMHz) const {
    const auto path = (dir_ / name).string();
    std::ofstream(path) << nlohmann::json{{"status", "ok"}, {"result_valid", true}, {"m", m}, {"arch", "stream"},
                                          {"ecp5", {{"fmax_mhz", fmaxMHz}}}}
                               .dump();
    return path;
  }
  std::string dir() const { return dir_.string(); }

 private:
  std::filesystem::path dir_;
};

ProfileInputs inputs(const ReportDir& reports, std::string lfe5uReport) {
  return {.device = {8, "stream", 32}, .fpgaDir = reports.dir(), .lfe5uReport = std::move(lfe5uReport)};
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST(DeviceProfile, RawRatesAreLanesTimesLineRateTimesEncoding) {
  EXPECT_DOUBLE_EQ(rawLinkBytesPerSecond(1, 5.0, 8, 10), 500e6);                  // Gen2 x1
  EXPECT_DOUBLE_EQ(rawLinkBytesPerSecond(8, 8.0, 128, 130), 8 * 8e9 * 128 / 130 / 8);  // Gen3 x8: 7.88 GB/s
  EXPECT_NEAR(rawLinkBytesPerSecond(8, 8.0, 128, 130), 7.877e9, 1e6);
  EXPECT_THROW(rawLinkBytesPerSecond(0, 5.0, 8, 10), std::invalid_argument);
  EXPECT_THROW(rawLinkBytesPerSecond(1, 5.0, 10, 8), std::invalid_argument);
}

TEST(DeviceProfile, TransferTimeOnEachBuiltInLinkMatchesTheFormulaByHand) {
  const ReportDir reports("bpaccel-profile-transfer");
  const auto in = inputs(reports, "");
  RunStats s;
  s.batches = 2;
  s.boxesSent = 1000;    // 24 kB
  s.loadCycles = 1000;   // 10 us through the load port at 100 MHz
  s.beatsReceived = 250; // 1 kB
  // ecp5-5g: 400 MB/s, 1 us. Boxes take 60 us on the link, 50 us more than the port.
  const LinkModel slow = ecp5FiveGProfile(in).linkModel(24, 4);
  EXPECT_DOUBLE_EQ(slow.bandwidthBytesPerSecond, 400e6);
  EXPECT_DOUBLE_EQ(slow.latencySeconds, 1e-6);
  EXPECT_NEAR(transferSeconds(s, slow, 100e6), 2e-6 + 50e-6 + 2.5e-6, 1e-12);
  // gen3x8: 6.5 GB/s, 1 us. Boxes take 3.7 us, less than the port: only the latencies and the results count.
  const LinkModel fast = gen3x8Profile(in).linkModel(24, 4);
  EXPECT_DOUBLE_EQ(fast.bandwidthBytesPerSecond, 6.5e9);
  EXPECT_NEAR(transferSeconds(s, fast, 100e6), 2e-6 + 1000 / 6.5e9, 1e-12);
}

TEST(DeviceProfile, EachLinkFigureSaysWhetherItIsSpecifiedOrAssumed) {
  const ReportDir reports("bpaccel-profile-link");
  for (const auto& p : {ecp5FiveGProfile(inputs(reports, "")), gen3x8Profile(inputs(reports, ""))}) {
    EXPECT_EQ(p.link.rawBytesPerSecond.provenance, Provenance::Specified) << p.name;
    EXPECT_EQ(p.link.effectiveBytesPerSecond.provenance, Provenance::Assumed) << p.name;
    EXPECT_EQ(p.link.latencySeconds.provenance, Provenance::Assumed) << p.name;
    EXPECT_LT(p.link.effectiveBytesPerSecond.value, p.link.rawBytesPerSecond.value) << p.name;
    const auto j = p.toJson();
    EXPECT_EQ(j["link"]["effective_bytes_per_second_each_way"]["provenance"], "assumed") << p.name;
    EXPECT_EQ(j["link"]["raw_bytes_per_second_each_way"]["provenance"], "specified") << p.name;
    EXPECT_FALSE(j["link"]["latency_seconds_per_transfer"]["source"].get<std::string>().empty()) << p.name;
    EXPECT_EQ(j["summary"], p.summary());
  }
  const auto five = ecp5FiveGProfile(inputs(reports, ""));
  EXPECT_EQ(five.link.generation, "PCIe Gen2");
  EXPECT_EQ(five.link.lanes, 1u);
  EXPECT_DOUBLE_EQ(five.link.rawBytesPerSecond.value, 500e6);
  const auto gen3 = gen3x8Profile(inputs(reports, ""));
  EXPECT_EQ(gen3.link.lanes, 8u);
  EXPECT_NEAR(gen3.link.rawBytesPerSecond.value, 7.877e9, 1e6);
}

TEST(DeviceProfile, AbsentFiveGReportSaysSoAndRunsOnTheLfe5uClockAsAStandIn) {
  const ReportDir reports("bpaccel-profile-absent");
  const auto lfe5u = reports.write("stream-m8.json", 8, 105.63);
  const auto p = ecp5FiveGProfile(inputs(reports, lfe5u));
  EXPECT_EQ(p.part.name, "LFE5UM5G-85F");
  EXPECT_EQ(p.part.speedGrade, 8);
  EXPECT_FALSE(p.part.reportPresent);
  EXPECT_TRUE(contains(p.part.report, "none found")) << p.part.report;
  EXPECT_DOUBLE_EQ(p.part.clockHz.value, 105.63e6);
  EXPECT_EQ(p.part.clockHz.provenance, Provenance::StandIn);
  EXPECT_TRUE(contains(p.part.clockHz.source, "no LFE5UM5G-85F report")) << p.part.clockHz.source;
  EXPECT_TRUE(contains(p.part.clockHz.source, "stand-in: LFE5U-85F speed 6 clock")) << p.part.clockHz.source;
  const auto j = p.toJson();
  EXPECT_EQ(j["part"]["report_present"], false);
  EXPECT_EQ(j["part"]["clock_hz"]["provenance"], "stand-in");
  EXPECT_TRUE(contains(p.summary(), "(stand-in)")) << p.summary();

  // The Gen3 x8-class card names no part: always the stand-in.
  const auto gen3 = gen3x8Profile(inputs(reports, lfe5u));
  EXPECT_EQ(gen3.part.clockHz.provenance, Provenance::StandIn);
  EXPECT_DOUBLE_EQ(gen3.part.clockHz.value, 105.63e6);

  // Without the LFE5U-85F report either, the clock is the default, and says it is assumed.
  const auto none = ecp5FiveGProfile(inputs(reports, reports.dir() + "/missing.json"));
  EXPECT_EQ(none.part.clockHz.provenance, Provenance::Assumed);
  EXPECT_DOUBLE_EQ(none.part.clockHz.value, 100e6);
  EXPECT_TRUE(contains(none.part.clockHz.source, "no FPGA report")) << none.part.clockHz.source;
}

TEST(DeviceProfile, AFiveGReportOfTheBuiltDeviceGivesAMeasuredClockAndOnlyThatOne) {
  const ReportDir reports("bpaccel-profile-present");
  const auto lfe5u = reports.write("stream-m8.json", 8, 105.63);
  reports.write("stream-m64-um5g.json", 64, 140.0);  // another design: never picked
  EXPECT_EQ(findFiveGReport(inputs(reports, lfe5u)), "");
  const auto wrongM = reports.write("stream-m8-um5g.json", 16, 150.0);  // named as ours, but of m = 16
  auto p = ecp5FiveGProfile(inputs(reports, lfe5u));
  EXPECT_EQ(p.part.report, wrongM);
  EXPECT_TRUE(p.part.reportPresent);
  EXPECT_EQ(p.part.clockHz.provenance, Provenance::StandIn);
  EXPECT_TRUE(contains(p.part.clockHz.source, "m = 16, not 8")) << p.part.clockHz.source;

  const auto ours = reports.write("stream-m8-um5g.json", 8, 131.5);
  p = ecp5FiveGProfile(inputs(reports, lfe5u));
  EXPECT_EQ(p.part.report, ours);
  EXPECT_EQ(p.part.clockHz.provenance, Provenance::Measured);
  EXPECT_DOUBLE_EQ(p.part.clockHz.value, 131.5e6);
  EXPECT_TRUE(contains(p.part.clockHz.source, ours)) << p.part.clockHz.source;
}

TEST(DeviceProfile, AProfiledDeviceTakesItsClockAndLinkAndKeepsItsOwnBoxAndBeatSizes) {
  const ReportDir reports("bpaccel-profile-device");
  const auto profile = ecp5FiveGProfile(inputs(reports, reports.write("stream-m8.json", 8, 105.63)));
  DeviceConfig device;
  device.link.bytesPerBox = 12;
  device.link.bytesPerBeat = 8;
  const DeviceConfig d = withProfile(device, profile);
  EXPECT_DOUBLE_EQ(d.clockHz, 105.63e6);
  EXPECT_DOUBLE_EQ(d.link.bandwidthBytesPerSecond, 400e6);
  EXPECT_DOUBLE_EQ(d.link.latencySeconds, 1e-6);
  EXPECT_DOUBLE_EQ(d.link.bytesPerBox, 12);
  EXPECT_DOUBLE_EQ(d.link.bytesPerBeat, 8);
  ASSERT_TRUE(d.profile.has_value());
  EXPECT_EQ(d.profile->name, "ecp5-5g");
  EXPECT_TRUE(contains(d.clockSource, "stand-in")) << d.clockSource;
}

TEST(DeviceProfile, AnUnknownProfileIsRefusedNamingTheKnownOnes) {
  try {
    builtInProfile("gen5x16", {});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_TRUE(contains(e.what(), "gen5x16") && contains(e.what(), "ecp5-5g")) << e.what();
  }
}
