#pragma once
// The scene files (.aabbs) of Broadmark, the broad-phase testing framework
// (github.com/ppgia-unifor/Broadmark): one header, then every frame's boxes.
//
// Layout (little-endian; Broadmark's SimulationGenerator writes it with C#'s
// BinaryWriter and its C++ side reads it as the struct SceneHeader and an
// array of Aabb):
//
//   byte   0  char[128]  scene name: printable ASCII, then zeros (at least one)
//   byte 128  char[128]  objects type ("Cubes", "Spheres", "Assorted"), the same way
//   byte 256  int32      objects N (> 0)
//   byte 260  int32      frames F (> 0): the steps after the initial frame
//   byte 264  int32 x 2  padding, 0
//   byte 272  box        the world's box
//   byte 304  box x N    frame 0: the initial positions; then frames 1 .. F
//
// A box is 32 bytes: min x, y, z, 0 then max x, y, z, 0 as float32. The
// file holds F + 1 frames and is exactly 304 + 32 N (F + 1) bytes long.

#include <cstdint>
#include <istream>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "types.hpp"

namespace bpaccel {

inline constexpr std::uint64_t kBroadmarkHeaderBytes = 304;
inline constexpr std::uint64_t kBroadmarkBoxBytes = 32;

/// A malformed .aabbs file: names the byte offset where the fault lies and the reason.
class BroadmarkError : public std::runtime_error {
 public:
  BroadmarkError(std::uint64_t offset, const std::string& reason);
  std::uint64_t offset() const { return offset_; }

 private:
  std::uint64_t offset_;
};

/// The header's fields.
struct BroadmarkHeader {
  std::string sceneName;
  std::string objectsType;
  std::uint32_t objects = 0;
  /// Broadmark's frame count: the frames after the initial one.
  std::uint32_t steps = 0;
  Aabb world{};
  /// Frames in the file, the initial one included (0 .. steps).
  std::uint64_t frames() const { return std::uint64_t{steps} + 1; }
};

/// Reads a .aabbs file frame by frame. The constructor checks the header
/// (names, counts, padding, world box) and that the file's size is exactly
/// what the header promises, so a truncated file or one with bytes to spare
/// is refused before any frame is read. Every error is a BroadmarkError.
class BroadmarkReader {
 public:
  /// `in` must be seekable (a file or a string stream) and outlive the reader.
  explicit BroadmarkReader(std::istream& in);
  const BroadmarkHeader& header() const { return header_; }
  /// Frame `frame`'s boxes (0: the initial positions). Throws std::out_of_range
  /// for a frame the file does not hold, and BroadmarkError naming the frame,
  /// the box and the field for a box with NaN, min > max, or a fourth float
  /// that is not 0; infinities are boxes, as in the text format.
  std::vector<Aabb> readFrame(std::uint64_t frame);

 private:
  std::istream& in_;
  BroadmarkHeader header_;
};

/// The header's names, which Broadmark requires: 1 to 127 printable ASCII characters each.
struct BroadmarkNames {
  std::string sceneName = "bpaccel";
  std::string objectsType = "Assorted";
};

/// Writes `frames` (at least two, as Broadmark's scenes hold an initial frame
/// and at least one step; each of the same positive number of boxes) as a
/// .aabbs file whose world box is the union of every frame's boxes. Throws
/// std::invalid_argument, before writing anything, naming what Broadmark
/// would refuse: too few frames, counts that differ, a name it cannot read,
/// a box with NaN or min > max.
void writeBroadmark(std::ostream& out, const BroadmarkNames& names, std::span<const std::vector<Aabb>> frames);

}  // namespace bpaccel
