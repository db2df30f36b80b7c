#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <thread>

#include <fmt/format.h>

#include "apps/run_cli.hpp"
#include "core/box_file.hpp"
#include "scenes.hpp"

namespace {

using bpaccel::testing::CliResult;

// `bpaccel pairs` on a text file holding `content`.
CliResult runCli(const std::string& content, const std::string& args) {
  const auto input = bpaccel::testing::cliTestDir() / "boxes.txt";
  std::ofstream(input) << content;
  return bpaccel::testing::runBpaccel("pairs --input " + input.string() + " " + args);
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

namespace {

// The pairs as the program prints them.
std::string pairsText(const std::vector<bpaccel::Pair>& pairs) {
  std::string text;
  for (const auto& [i, j] : bpaccel::testing::sorted(pairs)) text += fmt::format("{} {}\n", i, j);
  return text;
}

std::string boxesText(const std::vector<bpaccel::Aabb>& boxes) {
  std::ostringstream text;
  bpaccel::writeBoxes(text, boxes);
  return text.str();
}

std::size_t hardwareThreads() { return std::max(1u, std::thread::hardware_concurrency()); }

}  // namespace

// A newcomer's first command: no option but the input. It must be the
// software backend, its partition and cell size chosen for the scene (a
// partition, not one cell of 3000 boxes), on every hardware thread, and exact.
TEST(Cli, TheDefaultIsTheCpuBackendWithItsOwnPartitionOnEveryCore) {
  const auto boxes = bpaccel::testing::scatteredBoxes(3000, 45, 0, 1000, 1, 30);
  const auto r = runCli(boxesText(boxes), "--stats");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, pairsText(bpaccel::testing::bruteForce(boxes)));
  const std::regex fastPath(fmt::format(R"(^backend cpu threads {} cell-size [0-9]+ \(auto\) partition (grid|k-d) )"
                                        R"(\(auto\) objects 3000 )",
                                        hardwareThreads()));
  EXPECT_TRUE(std::regex_search(r.err, fastPath)) << r.err;
  // The cells it ran, which the next frame's choice of cell size reads.
  EXPECT_TRUE(std::regex_search(r.err, std::regex(R"(\ncells [1-9][0-9]* entries [1-9][0-9]* entries-per-box [0-9.]+ )"
                                                  R"(mean-cell [0-9.]+\n)")))
      << r.err;
}

TEST(Cli, TheHardwareBackendsAreOneOptionAwayOnOneDevice) {
  for (const char* backend : {"rtl", "model"}) {
    const auto r = runCli(kScene, std::string("--backend ") + backend + " --stats");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out, "0 1\n0 3\n") << backend;
    EXPECT_NE(r.err.find(fmt::format("backend {} threads 1 ", backend)), std::string::npos) << r.err;
  }
}

TEST(Cli, ThreadsAndAFixedPartitionAreHonoured) {
  const auto boxes = bpaccel::testing::scatteredBoxes(500, 7, 0, 100, 1, 10);
  const std::string expected = pairsText(bpaccel::testing::bruteForce(boxes));
  for (const char* threads : {"1", "2", "3"})
    for (const char* backend : {"cpu", "model"}) {
      const auto r = runCli(boxesText(boxes), fmt::format("--backend {} --threads {} --stats", backend, threads));
      EXPECT_EQ(r.exitCode, 0) << r.err;
      EXPECT_EQ(r.out, expected) << backend << " " << threads;
      EXPECT_NE(r.err.find(fmt::format("backend {} threads {} ", backend, threads)), std::string::npos) << r.err;
    }
  const auto r = runCli(boxesText(boxes), "--cell-size 32 --stats");
  EXPECT_EQ(r.out, expected);
  EXPECT_NE(r.err.find("cell-size 32 partition k-d objects"), std::string::npos) << r.err;
  const auto grid = runCli(boxesText(boxes), "--partition grid --stats");
  EXPECT_EQ(grid.out, expected);
  EXPECT_NE(grid.err.find(" (auto) partition grid objects"), std::string::npos) << grid.err;
}

TEST(Cli, HelpSaysWhenToUseEachBackend) {
  const auto r = bpaccel::testing::runBpaccel("pairs --help");
  EXPECT_EQ(r.exitCode, 0);
  // CLI11 wraps long help text; compare with the line breaks taken out.
  const std::string help = std::regex_replace(r.out, std::regex(R"(\s+)"), " ");
  for (const char* use : {"cpu: the answer, fast", "model: the device's cycle counts",
                          "rtl: to check the hardware itself"})
    EXPECT_NE(help.find(use), std::string::npos) << use << " in " << r.out;
  EXPECT_TRUE(std::regex_search(help, std::regex(R"(--backend \S*=cpu )"))) << r.out;
}
