#include <gtest/gtest.h>

#include <cstdint>

#include "partition/automatic_choice.hpp"

using namespace bpaccel;

namespace {

// The occupancy of cells whose box-weighted mean cell is `mean`: one cell of `mean` boxes.
CellOccupancy meanCellOf(std::uint64_t mean) { return {mean, mean, mean * mean, 1}; }

constexpr std::size_t kBoxes = 8000;
const KeyBounds kBounds{};

// The cell sizes MeanCellBand picks, frame by frame, when every frame's mean cell is `mean`.
std::vector<std::size_t> sizesUnder(std::uint64_t mean, int frames, PartitionKind kind = PartitionKind::Automatic) {
  AutomaticChoice rule(SizeRule::MeanCellBand);
  std::vector<std::size_t> sizes;
  for (int f = 0; f < frames; ++f) {
    const CellChoice c = rule.choose(kBoxes, kBounds, kind);
    sizes.push_back(*c.cellSize);
    rule.observe(c, meanCellOf(mean));
  }
  return sizes;
}

}  // namespace

TEST(AutomaticChoice, TheBandHalvesTheCellSizeAfterCellsAboveItDownToTheSmallest) {
  EXPECT_EQ(sizesUnder(AutomaticChoice::kMeanCellHigh + 1, 5), (std::vector<std::size_t>{64, 32, 16, 16, 16}));
}

TEST(AutomaticChoice, TheBandDoublesTheCellSizeAfterCellsBelowItUpToTheLargest) {
  EXPECT_EQ(sizesUnder(AutomaticChoice::kMeanCellLow - 1, 6), (std::vector<std::size_t>{64, 128, 256, 512, 512, 512}));
}

TEST(AutomaticChoice, TheBandKeepsTheCellSizeWhileTheMeanCellIsInIt) {
  for (auto mean : {AutomaticChoice::kMeanCellLow, 40.0, AutomaticChoice::kMeanCellHigh})
    EXPECT_EQ(sizesUnder(static_cast<std::uint64_t>(mean), 4), (std::vector<std::size_t>(4, 64))) << mean;
}

TEST(AutomaticChoice, TheBandIsWiderThanTheStepSoASizeNeverSwingsBetweenTwo) {
  // Doubling the size at most doubles the mean cell: a mean just under the
  // band, doubled, lands inside it, and one just over it, halved, too.
  EXPECT_LT(2 * AutomaticChoice::kMeanCellLow, AutomaticChoice::kMeanCellHigh);
}

TEST(AutomaticChoice, TheBandFollowsANamedPartitionAndTheFixedRuleNeverMoves) {
  EXPECT_EQ(sizesUnder(1000, 3, PartitionKind::KdTree), (std::vector<std::size_t>{64, 32, 16}));
  AutomaticChoice fixed(SizeRule::Fixed);
  for (int f = 0; f < 3; ++f) {
    const CellChoice c = fixed.choose(kBoxes, kBounds, PartitionKind::Automatic);
    EXPECT_EQ(c, (CellChoice{PartitionKind::UniformGrid, AutomaticChoice::kFirstCellSize}));
    fixed.observe(c, meanCellOf(1000));
  }
}

TEST(AutomaticChoice, AFrameOfOneCellOrOfAnotherKindTellsTheBandNothing) {
  AutomaticChoice rule(SizeRule::MeanCellBand);
  rule.observe({PartitionKind::UniformGrid, std::nullopt}, meanCellOf(1000));
  EXPECT_EQ(rule.choose(kBoxes, kBounds, PartitionKind::Automatic).cellSize, AutomaticChoice::kFirstCellSize);
  rule.observe({PartitionKind::KdTree, 64}, meanCellOf(1000));
  EXPECT_EQ(rule.choose(kBoxes, kBounds, PartitionKind::UniformGrid).cellSize, AutomaticChoice::kFirstCellSize);
  // Small scenes stay one cell whatever came before.
  rule.observe({PartitionKind::UniformGrid, 64}, meanCellOf(1000));
  EXPECT_EQ(rule.choose(AutomaticChoice::kOneCellUpTo, kBounds, PartitionKind::Automatic).cellSize, std::nullopt);
}
