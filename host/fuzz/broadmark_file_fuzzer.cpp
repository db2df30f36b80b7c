// BroadmarkReader on any bytes: either a header and frames that obey the
// format's rules, or a BroadmarkError whose byte offset lies where the fault
// is: within the file, and for a bad box at that box in the frame read.
// Anything else (a crash, a sanitizer report, a hang, another exception type)
// is a bug. A file whose every frame reads must also write back
// (writeBroadmark) and read again bit for bit.

#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/broadmark_file.hpp"
#include "fuzz_check.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using bpaccel::fuzz::require;
using bpaccel::testing::sameBits;

namespace {

void checkError(const BroadmarkError& e, std::size_t size) {
  require(e.offset() <= size, "error at byte {} of a {}-byte file: {}", e.offset(), size, e.what());
  require(std::string_view(e.what()).starts_with(fmt::format("byte {}: ", e.offset())),
          "message does not start with its byte: {}", e.what());
}

void checkHeader(const BroadmarkHeader& h, std::size_t size) {
  require(h.objects > 0 && h.steps > 0, "accepted {} objects, {} steps", h.objects, h.steps);
  require(size == kBroadmarkHeaderBytes + kBroadmarkBoxBytes * h.objects * h.frames(),
          "accepted {} bytes for {} frames of {} boxes", size, h.frames(), h.objects);
  for (const std::string* name : {&h.sceneName, &h.objectsType}) {
    require(!name->empty() && name->size() < 128, "accepted a name of {} characters", name->size());
    for (char c : *name) require(c >= 0x20 && c <= 0x7e, "accepted a name with byte {:#x}", c);
  }
}

// Frame f's boxes, or nothing when a box is refused (at a box of that frame).
std::optional<std::vector<Aabb>> readFrame(BroadmarkReader& reader, std::uint64_t f) {
  const BroadmarkHeader& h = reader.header();
  const std::uint64_t start = kBroadmarkHeaderBytes + f * kBroadmarkBoxBytes * h.objects;
  try {
    std::vector<Aabb> boxes = reader.readFrame(f);
    require(boxes.size() == h.objects, "frame {} has {} boxes, the header {}", f, boxes.size(), h.objects);
    for (const Aabb& b : boxes)
      for (int a = 0; a < 3; ++a)
        require(!std::isnan(b.min[a]) && !std::isnan(b.max[a]) && b.min[a] <= b.max[a],
                "frame {} holds a box with NaN or min > max", f);
    return boxes;
  } catch (const BroadmarkError& e) {
    require(e.offset() >= start && e.offset() < start + kBroadmarkBoxBytes * h.objects &&
                (e.offset() - start) % kBroadmarkBoxBytes == 0,
            "frame {} (bytes {} on) refused at byte {}, not at one of its boxes: {}", f, start, e.offset(), e.what());
    return std::nullopt;
  }
}

void checkRoundTrip(const BroadmarkHeader& h, const std::vector<std::vector<Aabb>>& frames) {
  std::stringstream file;
  writeBroadmark(file, {.sceneName = h.sceneName, .objectsType = h.objectsType}, frames);
  BroadmarkReader again(file);
  require(again.header().sceneName == h.sceneName && again.header().objectsType == h.objectsType &&
              again.header().objects == h.objects && again.header().steps == h.steps,
          "the header changed in a round trip");
  for (std::uint64_t f = 0; f < frames.size(); ++f) {
    const auto boxes = again.readFrame(f);
    for (std::size_t i = 0; i < boxes.size(); ++i)
      require(sameBits(boxes[i], frames[f][i]), "frame {} box {} changed in a round trip", f, i);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::optional<BroadmarkReader> reader;
  try {
    reader.emplace(in);
  } catch (const BroadmarkError& e) {
    checkError(e, size);
    return 0;
  }
  const BroadmarkHeader& h = reader->header();
  checkHeader(h, size);
  std::vector<std::vector<Aabb>> frames;
  bool allRead = true;
  for (std::uint64_t f = 0; f < h.frames(); ++f) {
    auto boxes = readFrame(*reader, f);
    allRead = allRead && boxes.has_value();
    if (boxes) frames.push_back(std::move(*boxes));
  }
  try {
    reader->readFrame(h.frames());
    require(false, "frame {} read from a file of {} frames", h.frames(), h.frames());
  } catch (const std::out_of_range&) {
  }
  if (allRead) checkRoundTrip(h, frames);
  return 0;
}
