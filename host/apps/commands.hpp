#pragma once
// The subcommands of `bpaccel`: their settings and what runs them. Each
// returns the program's exit code (0 done, 1 a malformed input, 2 a usage
// error) and prints its errors to stderr.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace bpaccel::app {

/// `bpaccel pairs`: the defaults give the fastest exact answer (the cpu
/// backend, partition and cell size chosen per frame, every hardware thread).
struct PairsOptions {
  std::string input;
  std::optional<std::uint64_t> frame;  // of a .aabbs scene
  std::string backend = "cpu";
  std::string cellSize = "auto";
  std::string partition = "auto";
  std::size_t threads = 0;  // 0: every hardware thread for cpu, one for rtl and model
  std::size_t cellsPerBatch = 1;
  std::size_t repeat = 1;
  bool stats = false;
};
int runPairs(const PairsOptions& options);

/// `bpaccel convert`: a scene from one format to the other.
struct ConvertOptions {
  std::string input, output;
  std::optional<std::uint64_t> frame;  // of a .aabbs input
};
int runConvert(const ConvertOptions& options);

}  // namespace bpaccel::app
