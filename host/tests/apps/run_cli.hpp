#pragma once
// Runs the real bpaccel binary and keeps its exit code, stdout and stderr.

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace bpaccel::testing {

struct CliResult {
  int exitCode;
  std::string out;
  std::string err;
};

/// A folder of this test process's own for the files a test hands the program.
inline std::filesystem::path cliTestDir() {
  const auto dir = std::filesystem::temp_directory_path() / ("bpaccel-cli-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

/// `bpaccel <args>`.
inline CliResult runBpaccel(const std::string& args) {
  const auto err = cliTestDir() / "err.txt";
  const std::string cmd = std::string(BPACCEL_CLI) + " " + args + " 2>" + err.string();
  CliResult r{};
  FILE* pipe = ::popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  std::size_t got;
  while ((got = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), got);
  r.exitCode = WEXITSTATUS(::pclose(pipe));
  std::ifstream e(err);
  r.err.assign(std::istreambuf_iterator<char>(e), {});
  return r;
}

inline std::string fileText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace bpaccel::testing
