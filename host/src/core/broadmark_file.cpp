#include "broadmark_file.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "box_file.hpp"
#include "keys.hpp"

namespace bpaccel {

BroadmarkError::BroadmarkError(std::uint64_t offset, const std::string& reason)
    : std::runtime_error(fmt::format("byte {}: {}", offset, reason)), offset_(offset) {}

namespace {

constexpr std::size_t kNameBytes = 128;
constexpr std::uint64_t kObjectsAt = 256, kStepsAt = 260, kPaddingAt = 264, kWorldAt = 272;
// Boxes read or written at a time: a frame of any size in bounded memory.
constexpr std::size_t kChunkBoxes = 8192;

std::uint32_t loadLe32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 | std::uint32_t{p[3]} << 24;
}

void storeLe32(std::uint32_t v, std::string& out) {
  for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>(v >> (8 * b) & 0xff));
}

/// The first fault of a name Broadmark cannot read, or empty.
std::string nameFault(std::string_view text) {
  if (text.empty()) return "is empty";
  if (text.size() >= kNameBytes) return fmt::format("has {} characters, at most {}", text.size(), kNameBytes - 1);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c > 0x7e) return fmt::format("character {} is 0x{:02x}, not printable ASCII", i, c);
  }
  return {};
}

/// A 128-byte name field: text, then zeros (at least one).
std::string readName(const unsigned char* field, std::uint64_t offset, const char* what) {
  const auto* zero = std::find(field, field + kNameBytes, 0);
  if (zero == field + kNameBytes) throw BroadmarkError(offset, fmt::format("{} has no terminating zero", what));
  const std::string text(reinterpret_cast<const char*>(field), static_cast<std::size_t>(zero - field));
  if (const std::string fault = nameFault(text); !fault.empty())
    throw BroadmarkError(offset, fmt::format("{} {}", what, fault));
  if (std::any_of(zero, field + kNameBytes, [](unsigned char c) { return c != 0; }))
    throw BroadmarkError(offset, fmt::format("{} has nonzero bytes after its terminating zero", what));
  return text;
}

/// A 32-byte box; throws BroadmarkError, the reason led by `what`, for NaN,
/// a fourth float that is not 0, or min > max.
Aabb readBox(const unsigned char* p, std::uint64_t offset, const std::string& what) {
  std::array<float, 8> v;
  for (int k = 0; k < 8; ++k) v[k] = std::bit_cast<float>(loadLe32(p + 4 * k));
  const Aabb box{{v[0], v[1], v[2]}, {v[4], v[5], v[6]}};
  std::string fault = boxFault(box);
  if (fault.empty() && v[3] != 0.0f) fault = fmt::format("min's fourth float is {}, not 0", v[3]);
  if (fault.empty() && v[7] != 0.0f) fault = fmt::format("max's fourth float is {}, not 0", v[7]);
  if (!fault.empty()) throw BroadmarkError(offset, fmt::format("{}: {}", what, fault));
  return box;
}

void storeBox(const Aabb& box, std::string& out) {
  for (const auto* corner : {&box.min, &box.max}) {
    for (const float f : *corner) storeLe32(std::bit_cast<std::uint32_t>(f), out);
    storeLe32(0, out);
  }
}

/// The stream's length in bytes, leaving it at the start.
std::uint64_t lengthOf(std::istream& in) {
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  in.seekg(0, std::ios::beg);
  if (end < 0 || !in) throw BroadmarkError(0, "cannot find the file's length (a .aabbs file must be seekable)");
  return static_cast<std::uint64_t>(end);
}

/// The header's counts and padding, checked.
void readCounts(const unsigned char* header, BroadmarkHeader& h) {
  const auto objects = static_cast<std::int32_t>(loadLe32(header + kObjectsAt));
  const auto steps = static_cast<std::int32_t>(loadLe32(header + kStepsAt));
  if (objects <= 0) throw BroadmarkError(kObjectsAt, fmt::format("number of objects {} is not positive", objects));
  if (static_cast<std::uint64_t>(objects) > kMaxObjects)
    throw BroadmarkError(kObjectsAt, fmt::format("{} objects are too many for 32-bit indices", objects));
  if (steps <= 0)
    throw BroadmarkError(kStepsAt, fmt::format("number of frames {} is not positive (a scene holds an initial "
                                               "frame and at least one more)",
                                               steps));
  for (std::uint64_t at : {kPaddingAt, kPaddingAt + 4})
    if (const std::uint32_t pad = loadLe32(header + at); pad != 0)
      throw BroadmarkError(at, fmt::format("padding is {}, not 0", pad));
  h.objects = static_cast<std::uint32_t>(objects);
  h.steps = static_cast<std::uint32_t>(steps);
}

/// Checks that `length` is exactly the header's promise; names the frame a
/// truncated file ends in.
void checkLength(std::uint64_t length, const BroadmarkHeader& h) {
  const std::uint64_t frameBytes = kBroadmarkBoxBytes * h.objects;
  const std::uint64_t body = length - kBroadmarkHeaderBytes;
  const std::uint64_t whole = body / frameBytes, rest = body % frameBytes;
  if (whole < h.frames())
    throw BroadmarkError(length, fmt::format("truncated: the header promises frames 0 to {} of {} boxes ({} bytes "
                                             "each); the file ends in frame {}, after {} of its bytes",
                                             h.steps, h.objects, frameBytes, whole, rest));
  const std::uint64_t end = kBroadmarkHeaderBytes + h.frames() * frameBytes;
  if (length != end)
    throw BroadmarkError(end, fmt::format("{} bytes after the last frame ({} frames of {} boxes)", length - end,
                                          h.frames(), h.objects));
}

}  // namespace

BroadmarkReader::BroadmarkReader(std::istream& in) : in_(in) {
  const std::uint64_t length = lengthOf(in_);
  if (length < kBroadmarkHeaderBytes)
    throw BroadmarkError(length, fmt::format("truncated header: the file has {} bytes, a header {}", length,
                                             kBroadmarkHeaderBytes));
  std::array<unsigned char, kBroadmarkHeaderBytes> header;
  if (!in_.read(reinterpret_cast<char*>(header.data()), header.size())) throw BroadmarkError(0, "read error");
  header_.sceneName = readName(header.data(), 0, "scene name");
  header_.objectsType = readName(header.data() + kNameBytes, kNameBytes, "objects type");
  readCounts(header.data(), header_);
  header_.world = readBox(header.data() + kWorldAt, kWorldAt, "world box");
  checkLength(length, header_);
}

std::vector<Aabb> BroadmarkReader::readFrame(std::uint64_t frame) {
  if (frame >= header_.frames())
    throw std::out_of_range(fmt::format("no frame {}: the scene holds frames 0 to {}", frame, header_.steps));
  const std::uint64_t start = kBroadmarkHeaderBytes + frame * kBroadmarkBoxBytes * header_.objects;
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(start));
  std::vector<Aabb> boxes;
  boxes.reserve(header_.objects);
  std::vector<unsigned char> chunk;
  while (boxes.size() < header_.objects) {
    const std::size_t count = std::min<std::size_t>(kChunkBoxes, header_.objects - boxes.size());
    const std::uint64_t offset = start + boxes.size() * kBroadmarkBoxBytes;
    chunk.resize(count * kBroadmarkBoxBytes);
    if (!in_.read(reinterpret_cast<char*>(chunk.data()), static_cast<std::streamsize>(chunk.size())))
      throw BroadmarkError(offset, fmt::format("read error in frame {}", frame));
    for (std::size_t k = 0; k < count; ++k) {
      const std::size_t index = boxes.size();
      boxes.push_back(readBox(chunk.data() + k * kBroadmarkBoxBytes, offset + k * kBroadmarkBoxBytes,
                              fmt::format("frame {}, box {}", frame, index)));
    }
  }
  return boxes;
}

namespace {

/// The union of every frame's boxes; throws std::invalid_argument for what Broadmark would refuse.
Aabb checkFrames(const BroadmarkNames& names, std::span<const std::vector<Aabb>> frames) {
  for (const auto& [name, what] : {std::pair{&names.sceneName, "scene name"}, {&names.objectsType, "objects type"}})
    if (const std::string fault = nameFault(*name); !fault.empty())
      throw std::invalid_argument(fmt::format(".aabbs: {} {}", what, fault));
  if (frames.size() < 2)
    throw std::invalid_argument(fmt::format(".aabbs: {} frames; a scene holds an initial frame and at least one more",
                                            frames.size()));
  const std::size_t objects = frames.front().size();
  const auto maxCount = static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  if (objects == 0) throw std::invalid_argument(".aabbs: a scene holds at least one box");
  if (objects > maxCount || frames.size() - 1 > maxCount)
    throw std::invalid_argument(".aabbs: more boxes or frames than the header's 32-bit counts hold");
  constexpr float kInf = std::numeric_limits<float>::infinity();
  Aabb world{{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}};
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].size() != objects)
      throw std::invalid_argument(
          fmt::format(".aabbs: frame {} has {} boxes, frame 0 has {}", f, frames[f].size(), objects));
    for (std::size_t i = 0; i < objects; ++i) {
      const Aabb& b = frames[f][i];
      if (const std::string fault = boxFault(b); !fault.empty())
        throw std::invalid_argument(fmt::format(".aabbs: frame {}, box {}: {}", f, i, fault));
      for (int a = 0; a < 3; ++a) {
        world.min[a] = std::min(world.min[a], b.min[a]);
        world.max[a] = std::max(world.max[a], b.max[a]);
      }
    }
  }
  return world;
}

void storeName(const std::string& text, std::string& out) {
  out += text;
  out.append(kNameBytes - text.size(), '\0');
}

}  // namespace

void writeBroadmark(std::ostream& out, const BroadmarkNames& names, std::span<const std::vector<Aabb>> frames) {
  const Aabb world = checkFrames(names, frames);
  std::string bytes;
  storeName(names.sceneName, bytes);
  storeName(names.objectsType, bytes);
  storeLe32(static_cast<std::uint32_t>(frames.front().size()), bytes);
  storeLe32(static_cast<std::uint32_t>(frames.size() - 1), bytes);
  storeLe32(0, bytes);
  storeLe32(0, bytes);
  storeBox(world, bytes);
  for (const auto& frame : frames)
    for (const Aabb& box : frame) {
      storeBox(box, bytes);
      if (bytes.size() >= kChunkBoxes * kBroadmarkBoxBytes) {
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        bytes.clear();
      }
    }
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace bpaccel
