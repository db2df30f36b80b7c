#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "apps/run_cli.hpp"
#include "core/box_file.hpp"
#include "core/broadmark_file.hpp"

using bpaccel::testing::cliTestDir;
using bpaccel::testing::fileText;
using bpaccel::testing::runBpaccel;

namespace {

// In the form writeBoxes prints, so a round trip must give it back byte for byte.
const char* kScene =
    "0 0 0 1 1 1\n"
    "1 0 0 2 1 1\n"
    "5 5 5 6 6 6\n"
    "-0 -0 -0 0.5 0.5 0.5\n"
    "-inf 7 1e-45 inf 7.5 3.4028235e+38\n";

std::filesystem::path writeText(const std::string& name, const std::string& text) {
  const auto path = cliTestDir() / name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A Broadmark scene of three frames that differ, written by the library.
std::filesystem::path threeFrameScene() {
  const std::vector<std::vector<bpaccel::Aabb>> frames = {
      {{{0, 0, 0}, {1, 1, 1}}, {{3, 0, 0}, {4, 1, 1}}},
      {{{0, 0, 0}, {1, 1, 1}}, {{1, 0, 0}, {2, 1, 1}}},
      {{{0, 0, 0}, {1, 1, 1}}, {{0.5f, 0.5f, 0.5f}, {2, 1, 1}}}};
  const auto path = cliTestDir() / "moving.aabbs";
  std::ofstream out(path, std::ios::binary);
  bpaccel::writeBroadmark(out, {.sceneName = "Moving"}, frames);
  return path;
}

}  // namespace

TEST(Convert, TextToAabbsToTextGivesTheSameFile) {
  const auto text = writeText("scene.txt", kScene);
  const auto aabbs = cliTestDir() / "scene.aabbs", back = cliTestDir() / "back.txt";
  auto r = runBpaccel("convert --input " + text.string() + " --output " + aabbs.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // A header, then the five boxes as frame 0 and as frame 1.
  EXPECT_EQ(fileText(aabbs).size(), 304u + 32u * 5u * 2u);
  EXPECT_EQ(fileText(aabbs).substr(0, 6), std::string("scene\0", 6));
  r = runBpaccel("convert --input " + aabbs.string() + " --output " + back.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(fileText(back), kScene);
  r = runBpaccel("convert --input " + aabbs.string() + " --frame 1 --output " + back.string());
  EXPECT_EQ(fileText(back), kScene);
}

TEST(Convert, PicksTheFrameOfAnAabbsScene) {
  const auto scene = threeFrameScene(), out = cliTestDir() / "frame.txt";
  const std::vector<std::string> expected = {"0 0 0 1 1 1\n3 0 0 4 1 1\n", "0 0 0 1 1 1\n1 0 0 2 1 1\n",
                                             "0 0 0 1 1 1\n0.5 0.5 0.5 2 1 1\n"};
  for (int frame = 0; frame < 3; ++frame) {
    const auto r = runBpaccel("convert --input " + scene.string() + " --frame " + std::to_string(frame) +
                              " --output " + out.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(fileText(out), expected[static_cast<std::size_t>(frame)]) << frame;
  }
}

TEST(Convert, PairsReadsAnAabbsSceneFrameByFrame) {
  const auto scene = threeFrameScene();
  EXPECT_EQ(runBpaccel("pairs --input " + scene.string()).out, "");
  EXPECT_EQ(runBpaccel("pairs --input " + scene.string() + " --frame 1").out, "0 1\n");
  const auto r = runBpaccel("pairs --input " + scene.string() + " --frame 2 --backend model --cell-size none");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, "0 1\n");
}

TEST(Convert, ErrorsNameTheFileAndTheCause) {
  const auto scene = threeFrameScene();
  auto r = runBpaccel("pairs --input " + scene.string() + " --frame 3");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("moving.aabbs: no frame 3: the scene holds frames 0 to 2"), std::string::npos) << r.err;

  const auto text = writeText("scene.txt", kScene);
  r = runBpaccel("pairs --input " + text.string() + " --frame 1");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("--frame picks a frame of a .aabbs scene; '" + text.string() + "' is a text box file"),
            std::string::npos)
      << r.err;

  const auto truncated = writeText("cut.aabbs", fileText(scene).substr(0, 400));
  r = runBpaccel("convert --input " + truncated.string() + " --output " + (cliTestDir() / "x.txt").string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("cut.aabbs: byte 400: truncated: the header promises frames 0 to 2 of 2 boxes"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.out, "");

  r = runBpaccel("pairs --input " + (cliTestDir() / "absent.aabbs").string());
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("cannot open"), std::string::npos) << r.err;

  // Broadmark has no empty scenes: refused, and no file is left behind.
  const auto empty = writeText("empty.txt", "# no boxes\n"), out = cliTestDir() / "empty.aabbs";
  r = runBpaccel("convert --input " + empty.string() + " --output " + out.string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("empty.aabbs: .aabbs: a scene holds at least one box"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));

  const auto bad = writeText("bad.txt", "0 0 0 1 1 1\n2 0 0 1 1 1\n");
  r = runBpaccel("convert --input " + bad.string() + " --output " + out.string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("bad.txt:line 2: minx 2 > maxx 1"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}
