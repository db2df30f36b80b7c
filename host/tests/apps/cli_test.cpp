#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

namespace {

struct Result {
  int exitCode;
  std::string out;
  std::string err;
};

// Runs the real bpaccel binary on a file holding `content`.
Result runCli(const std::string& content, const std::string& args) {
  const auto dir = std::filesystem::temp_directory_path() / ("bpaccel-cli-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto input = dir / "boxes.txt", err = dir / "err.txt";
  std::ofstream(input) << content;
  const std::string cmd = std::string(BPACCEL_CLI) + " pairs --input " + input.string() + " " + args + " 2>" +
                          err.string();
  Result r{};
  FILE* pipe = ::popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  std::size_t got;
  while ((got = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), got);
  r.exitCode = WEXITSTATUS(::pclose(pipe));
  std::ifstream e(err);
  r.err.assign(std::istreambuf_iterator<char>(e), {});
  return r;
}

const char* kScene =
    "# three boxes: 0 and 1 touch, 2 is apart\n"
    "0 0 0 1 1 1\n"
    "\n"
    "1 0 0 2 1 1\n"
    "5 5 5 6 6 6\n"
    "-0 -0 -0 0.5 0.5 0.5\n";

}  // namespace

TEST(Cli, PrintsSortedPairsForEveryBackendAndCellSize) {
  for (const char* backend : {"rtl", "model", "cpu"})
    for (const char* cell : {"none", "1", "2", "16"}) {
      const auto r = runCli(kScene, std::string("--backend ") + backend + " --cell-size " + cell);
      EXPECT_EQ(r.exitCode, 0) << r.err;
      EXPECT_EQ(r.out, "0 1\n0 3\n") << backend << " " << cell;
    }
}

TEST(Cli, BatchesOfCellsGiveTheSamePairsAsSingleRuns) {
  for (const char* backend : {"rtl", "model", "cpu"})
    for (const char* batch : {"1", "2", "3", "100"}) {
      const auto r = runCli(kScene, std::string("--backend ") + backend + " --cell-size 1 --cells-per-batch " + batch);
      EXPECT_EQ(r.exitCode, 0) << r.err;
      EXPECT_EQ(r.out, "0 1\n0 3\n") << backend << " " << batch;
    }
  const auto r = runCli(kScene, "--backend rtl --cell-size 1 --cells-per-batch 100 --stats");
  EXPECT_NE(r.err.find("batches 1 "), std::string::npos) << r.err;
  EXPECT_NE(runCli(kScene, "--cells-per-batch 0").exitCode, 0);
}

TEST(Cli, TheGridPartitionGivesTheSamePairsAndNamesItselfInTheStats) {
  for (const char* backend : {"rtl", "model", "cpu"})
    for (const char* cell : {"1", "2", "16"}) {
      const auto r = runCli(kScene, std::string("--backend ") + backend + " --cell-size " + cell +
                                        " --partition grid --repeat 3 --stats");
      EXPECT_EQ(r.exitCode, 0) << r.err;
      EXPECT_EQ(r.out, "0 1\n0 3\n") << backend << " " << cell;
      EXPECT_NE(r.err.find("partition grid"), std::string::npos) << r.err;
      EXPECT_NE(r.err.find("(median of 3 frames)"), std::string::npos) << r.err;
    }
  EXPECT_NE(runCli(kScene, "--partition octree").exitCode, 0);
}

TEST(Cli, StatsGoToStderr) {
  const auto r = runCli(kScene, "--backend rtl --stats");
  EXPECT_EQ(r.exitCode, 0);
  EXPECT_EQ(r.out, "0 1\n0 3\n");
  EXPECT_NE(r.err.find("cycles"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("host seconds (measured)"), std::string::npos) << r.err;
}

TEST(Cli, RejectsMalformedInputWithTheLineNumberAndPrintsNoPairs) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"0 0 0 1 1 1\n0 0 0 1 1\n", "line 2: 5 fields"},
      {"0 0 0 1 1 1\n\n0 0 zero 1 1 1\n", "line 3: minz 'zero' is not a number"},
      {"nan 0 0 1 1 1\n", "line 1: minx is NaN"},
      {"0 0 0 1 1 1\n2 0 0 1 1 1\n", "line 2: minx 2 > maxx 1"},
  };
  for (const auto& [content, message] : bad) {
    const auto r = runCli(content, "--backend cpu");
    EXPECT_EQ(r.exitCode, 1) << content;
    EXPECT_EQ(r.out, "") << content;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  }
}

TEST(Cli, RejectsBadOptions) {
  EXPECT_NE(runCli(kScene, "--backend gpu").exitCode, 0);
  const auto r = runCli(kScene, "--cell-size 0");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("--cell-size"), std::string::npos) << r.err;
}
