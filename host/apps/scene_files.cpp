#include "scene_files.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "core/box_file.hpp"
#include "core/broadmark_file.hpp"

namespace bpaccel::app {

namespace {

std::ifstream openForReading(const std::string& path, std::ios::openmode mode) {
  std::ifstream in(path, mode);
  if (!in) throw SceneFileError(2, fmt::format("cannot open '{}'", path));
  return in;
}

std::vector<Aabb> readBroadmarkFrame(const std::string& path, std::uint64_t frame) {
  std::ifstream in = openForReading(path, std::ios::binary);
  try {
    BroadmarkReader reader(in);
    return reader.readFrame(frame);
  } catch (const BroadmarkError& e) {
    throw SceneFileError(1, fmt::format("{}: {}", path, e.what()));
  } catch (const std::out_of_range& e) {
    throw SceneFileError(2, fmt::format("{}: {}", path, e.what()));
  }
}

/// The file's stem as a name Broadmark reads: printable ASCII, 1 to 127 characters.
std::string sceneNameOf(const std::string& path) {
  std::string name = std::filesystem::path(path).stem().string();
  for (char& c : name)
    if (c < 0x20 || c > 0x7e) c = '_';
  if (name.size() > 127) name.resize(127);
  return name.empty() ? "bpaccel" : name;
}

}  // namespace

bool isBroadmarkFile(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  return std::equal(ext.begin(), ext.end(), ".aabbs", ".aabbs" + 6,
                    [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
}

std::vector<Aabb> readSceneFile(const std::string& path, std::optional<std::uint64_t> frame) {
  if (isBroadmarkFile(path)) return readBroadmarkFrame(path, frame.value_or(0));
  if (frame)
    throw SceneFileError(2, fmt::format("--frame picks a frame of a .aabbs scene; '{}' is a text box file", path));
  std::ifstream in = openForReading(path, std::ios::in);
  try {
    return readBoxes(in);
  } catch (const ParseError& e) {
    throw SceneFileError(1, fmt::format("{}:{}", path, e.what()));
  }
}

void writeSceneFile(const std::string& path, std::span<const Aabb> boxes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw SceneFileError(2, fmt::format("cannot open '{}' for writing", path));
  if (isBroadmarkFile(path)) {
    const std::vector<Aabb> frame(boxes.begin(), boxes.end());
    const std::vector<Aabb> frames[] = {frame, frame};
    try {
      writeBroadmark(out, {.sceneName = sceneNameOf(path)}, frames);
    } catch (const std::invalid_argument& e) {
      out.close();
      std::filesystem::remove(path);  // nothing was written: leave no empty scene behind
      throw SceneFileError(1, fmt::format("{}: {}", path, e.what()));
    }
  } else {
    writeBoxes(out, boxes);
  }
  out.close();
  if (!out) throw SceneFileError(1, fmt::format("cannot write '{}'", path));
}

}  // namespace bpaccel::app
