#pragma once
// A named platform the accelerator is modelled on: an FPGA part with its
// place-and-route report, and the host link that part's card has. Every
// figure says whether it was measured for that part or assumed, and where it
// comes from, so a modelled frame names the platform it describes.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "link_model.hpp"

namespace bpaccel {

/// How a profile's figure is known.
enum class Provenance {
  Measured,   // for this part: its own place-and-route report
  Specified,  // for this part: a fixed rate of the standard its hard IP implements (lanes, line rate, encoding)
  Assumed,    // an estimate for this kind of card (overheads, latency): no measurement of it
  StandIn,   // measured, but on another part: a placeholder until this part's is measured
};
const char* provenanceName(Provenance p);

/// One figure of a profile, with how it is known and a short source.
struct ProfiledValue {
  double value = 0;
  Provenance provenance = Provenance::Assumed;
  std::string source;
};

/// The FPGA part and the clock the device runs at on it.
struct PartProfile {
  std::string name;         // e.g. LFE5UM5G-85F
  int speedGrade = 0;
  std::string report;       // the place-and-route report whose Fmax is this part's clock
  bool reportPresent = false;
  ProfiledValue clockHz;    // Measured from `report`, else a StandIn (or Assumed) clock, or Assumed from --clock-mhz
};

/// The host link: PCIe generation and lanes, rates each way and a latency per transfer.
struct LinkProfile {
  std::string generation;            // e.g. "PCIe Gen2"
  unsigned lanes = 1;                // 0: not given (a custom link)
  double gigaTransfersPerSecond = 0; // per lane
  std::string encoding;              // e.g. "8b/10b"
  ProfiledValue rawBytesPerSecond;   // each way: lanes x line rate x encoding efficiency
  ProfiledValue effectiveBytesPerSecond;  // each way, after packet (TLP) overhead: what the model uses
  ProfiledValue latencySeconds;      // a command reaching the device, or a completion the host
};

struct DeviceProfile {
  std::string name;         // what rows are named by: ecp5-5g, gen3x8, ...
  std::string description;
  PartProfile part;
  LinkProfile link;

  /// The link model of this profile for a device of `bytesPerBox` and `bytesPerBeat`.
  LinkModel linkModel(double bytesPerBox, double bytesPerBeat) const;
  /// Every field with its provenance and source.
  nlohmann::json toJson() const;
  /// One line for tables: the part, its clock and the link, each labelled.
  std::string summary() const;
};

/// Raw bytes per second each way of `lanes` lanes at `gigaTransfersPerSecond`
/// with `payloadBits` of every `lineBits` carrying data (8b/10b: 8 of 10).
double rawLinkBytesPerSecond(unsigned lanes, double gigaTransfersPerSecond, int payloadBits, int lineBits);

/// The built device, as an FPGA report must describe it.
struct BuiltDevice {
  int m = 0;
  std::string arch;
  int keyWidth = 32;
};

/// A part whose clock is the Fmax of `report` where that is a valid report of
/// `device` (the checks of clockFromFpgaReport), labelled Measured; where it
/// is absent or invalid, `standIn` (a clock measured on another part, or an
/// assumed one), its source prefixed with why.
PartProfile resolvePart(std::string name, int speedGrade, std::string report, const BuiltDevice& device,
                        const ProfiledValue& standIn);

/// What the built-in profiles are made from: the built device, where the FPGA
/// reports are, and the LFE5U-85F report that gives the stand-in clock.
struct ProfileInputs {
  BuiltDevice device;
  std::string fpgaDir = "results/fpga";
  std::string lfe5uReport;  // the LFE5U-85F speed 6 report of the built device
};

/// The LFE5UM5G-85F speed 8 with its Gen2 x1 PCIe endpoint.
DeviceProfile ecp5FiveGProfile(const ProfileInputs& in);
/// A PCIe Gen3 x8-class card: link assumed, the LFE5U-85F clock as a stand-in.
DeviceProfile gen3x8Profile(const ProfileInputs& in);
/// A link given on the command line (assumed), on the LFE5U-85F's clock.
DeviceProfile customLinkProfile(const ProfileInputs& in, double bytesPerSecond, double latencySeconds);
/// The names builtInProfile knows.
std::vector<std::string> builtInProfileNames();
/// The profile `name` (ecp5-5g, gen3x8); throws std::invalid_argument naming the known ones.
DeviceProfile builtInProfile(const std::string& name, const ProfileInputs& in);

/// The report of the LFE5UM5G-85F for the built device in `fpgaDir`: a file
/// named as the LFE5U-85F's (results/fpga/<design>.json) with "um5g" in the
/// rest of its name; empty where there is none.
std::string findFiveGReport(const ProfileInputs& in);
/// That report, or where it was looked for ("<fpgaDir>/<design>-*um5g*.json (none found)").
std::string fiveGReportOrPattern(const ProfileInputs& in);

}  // namespace bpaccel
