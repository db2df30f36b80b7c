#include <fmt/format.h>

#include "commands.hpp"
#include "scene_files.hpp"

namespace bpaccel::app {

int runConvert(const ConvertOptions& options) {
  try {
    writeSceneFile(options.output, readSceneFile(options.input, options.frame));
    return 0;
  } catch (const SceneFileError& e) {
    fmt::print(stderr, "bpaccel: {}\n", e.what());
    return e.exitCode();
  }
}

}  // namespace bpaccel::app
