#pragma once
// The FPGA flow's place-and-route reports (results/fpga/*.json) as the
// benchmark reads them: the measured clock of the built device.

#include <string>

namespace bpaccel {

/// A device clock and where it came from, for the table's legend.
struct DeviceClock {
  double hz = 100e6;
  std::string source = "default 100 MHz";
  bool measured = false;  // the Fmax of a valid report; false: the default, with the reason in `source`
};

/// The default clock of a device with m lanes of architecture `arch` and
/// `keyWidth`-bit keys: the Fmax that the FPGA flow's report at `fpgaReport`
/// measured, if that report is a valid result for the same m, architecture
/// and key width; otherwise 100 MHz, with the reason in `source`. Reports
/// without "arch" predate the stream architecture and are the seed's; those
/// without "key_width" are of 32-bit keys.
DeviceClock clockFromFpgaReport(const std::string& fpgaReport, int m, const std::string& arch, int keyWidth = 32);

/// The key width an architecture's report names leave out: 32, the binning
/// device's default (BinningParams) for it (scripts/fpga/fpgaflow/names.py).
int defaultKeyWidth(const std::string& arch);

/// Where the FPGA flow writes the report of that device (make fpga's FPGA_NAME):
/// results/fpga/[<arch>-]m<m>[-k<width>].json, no prefix for the seed, no suffix for the default key width.
std::string fpgaReportPath(int m, const std::string& arch, int keyWidth);

}  // namespace bpaccel
