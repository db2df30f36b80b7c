#pragma once
// The scene files `bpaccel` reads and writes: the text box format
// (core/box_file.hpp) and Broadmark's .aabbs scenes (core/broadmark_file.hpp),
// told apart by the name's extension.

#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace bpaccel::app {

/// A scene file the program cannot use; the message names the file and what
/// is wrong. exitCode: 2 for what the command line asked (a file that cannot
/// be opened, a frame the scene does not hold), 1 for a malformed file.
class SceneFileError : public std::runtime_error {
 public:
  SceneFileError(int exitCode, const std::string& message) : std::runtime_error(message), exitCode_(exitCode) {}
  int exitCode() const { return exitCode_; }

 private:
  int exitCode_;
};

/// A name ending in ".aabbs" (any case): Broadmark's format; any other: text.
bool isBroadmarkFile(const std::string& path);

/// The boxes of `path`; `frame` picks a frame of a .aabbs file (default 0,
/// its initial frame) and is refused for a text file.
std::vector<Aabb> readSceneFile(const std::string& path, std::optional<std::uint64_t> frame);

/// Writes `boxes` to `path` in the format its name gives. A .aabbs file gets
/// the boxes as its initial frame and as its one step (Broadmark's scenes
/// hold at least two frames), named after the file.
void writeSceneFile(const std::string& path, std::span<const Aabb> boxes);

}  // namespace bpaccel::app
