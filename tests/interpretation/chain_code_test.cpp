#include "bsls/interpretation/chain_code.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>

#include "bsls/interpretation/line_fill.h"

namespace bsls::interpretation {
namespace {

TEST(ChainCode, CodesRunAnticlockwiseFromPlusX) {
  EXPECT_EQ(DirectionCode(1, 0), 0);
  EXPECT_EQ(DirectionCode(0, -1), 2);  // up on the screen
  EXPECT_EQ(DirectionCode(-1, 0), 4);
  EXPECT_EQ(DirectionCode(0, 1), 6);
  EXPECT_EQ(DirectionCode(2, 0), -1);
  // Every unit step has its code, and nothing else has one.
  for (int c = 0; c < 8; ++c) EXPECT_EQ(DirectionCode(CodeStep(c).x, CodeStep(c).y), c) << c;
  for (int dy = -3; dy <= 3; ++dy)
    for (int dx = -3; dx <= 3; ++dx)
      if (std::max(std::abs(dx), std::abs(dy)) != 1) {
        EXPECT_EQ(DirectionCode(dx, dy), -1) << dx << " " << dy;
      }
}

TEST(ChainCode, DifferenceCodeFollowsEquation54) {
  EXPECT_EQ(DifferenceCode(0, 1), 1);
  EXPECT_EQ(DifferenceCode(7, 0), 1);  // wraps
  EXPECT_EQ(DifferenceCode(1, 7), -2);
  EXPECT_EQ(DifferenceCode(2, 6), 4);  // reversal: an end point
  EXPECT_EQ(DifferenceCode(6, 2), 4);
  EXPECT_EQ(InverseCode(6), 2);
}

TEST(ChainCode, EndPointsByCodesMatchEquation55) {
  // A vertical stub walked up then back down is a top end point.
  EXPECT_EQ(ClassifyEndByCodes(2, 2, 6), EndDirection::kTop);
  EXPECT_EQ(ClassifyEndByCodes(2, 1, 5), EndDirection::kTop);
  EXPECT_EQ(ClassifyEndByCodes(6, 6, 2), EndDirection::kBottom);
  EXPECT_EQ(ClassifyEndByCodes(0, 0, 4), EndDirection::kRight);
  EXPECT_EQ(ClassifyEndByCodes(4, 4, 0), EndDirection::kLeft);
  EXPECT_EQ(ClassifyEndByCodes(0, 0, 0), std::nullopt);
  // The stub direction gives the same classes.
  EXPECT_EQ(ClassifyEnd(0.1, 1.0), EndDirection::kTop);
  EXPECT_EQ(ClassifyEnd(-0.2, -1.0), EndDirection::kBottom);
  EXPECT_EQ(ClassifyEnd(-1.0, 0.3), EndDirection::kRight);
  EXPECT_EQ(ClassifyEnd(1.0, 0.3), EndDirection::kLeft);
}

TEST(ChainCode, ChainCodesRejectJumps) {
  EXPECT_EQ(ChainCodes({{0, 0}, {1, 1}, {1, 2}}), (std::vector<int>{7, 6}));
  EXPECT_THROW(ChainCodes({{0, 0}, {2, 0}}), std::invalid_argument);
}

TEST(LineFill, BresenhamIsEightConnectedAndHitsBothEnds) {
  for (const auto& [a, b] : std::vector<std::pair<cv::Point, cv::Point>>{
           {{0, 0}, {7, 3}}, {{5, 5}, {2, 17}}, {{3, 9}, {3, 1}}, {{0, 0}, {-6, -6}}}) {
    const auto line = BresenhamLine(a, b);
    ASSERT_EQ(line.front(), a);
    ASSERT_EQ(line.back(), b);
    EXPECT_EQ(static_cast<int>(line.size()),
              std::max(std::abs(b.x - a.x), std::abs(b.y - a.y)) + 1);
    EXPECT_NO_THROW(ChainCodes(line));
  }
}

}  // namespace
}  // namespace bsls::interpretation
