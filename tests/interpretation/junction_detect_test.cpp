#include "bsls/interpretation/junction_detect.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "bsls/interpretation/reference_line.h"
#include "bsls/testing/synthetic_brick.h"

namespace bsls::interpretation {
namespace {

cv::Mat Blank() { return cv::Mat::zeros(40, 40, CV_8UC1); }

// Thesis algorithm 5.2.3.1 on the four cases of Figures 5.18 and 5.20.
TEST(JunctionDetect, DirectAndCorrespondingTJunctions) {
  cv::Mat sk = Blank();
  cv::line(sk, {20, 5}, {20, 35}, 255);
  cv::line(sk, {20, 20}, {6, 21}, 255);  // segment to the left
  const JunctionDetection left = DetectJunction(sk, {20, 20}, pattern::Side::kLeft);
  ASSERT_TRUE(left.is_junction);
  EXPECT_EQ(left.attribute, JunctionAttribute::kDirect);  // left side: p grows leftwards
  EXPECT_NEAR(left.centre.x, 20.0, 1.0);
  EXPECT_NEAR(left.centre.y, 20.0, 1.0);
  EXPECT_LT(left.top.y, 20);
  EXPECT_GT(left.bottom.y, 20);
  EXPECT_LT(left.side.x, 20);
  const JunctionDetection right = DetectJunction(sk, {20, 20}, pattern::Side::kRight);
  EXPECT_EQ(right.attribute, JunctionAttribute::kCorresponding);
}

TEST(JunctionDetect, PlainLinePointIsDegreeTwo) {
  cv::Mat sk = Blank();
  cv::line(sk, {20, 5}, {20, 35}, 255);
  sk.at<uchar>(20, 21) = 255;  // a noisy pixel on the line's side (Figure 5.19 g)
  EXPECT_FALSE(DetectJunction(sk, {20, 20}, pattern::Side::kLeft).is_junction);
}

TEST(JunctionDetect, CrossingOfFourLinesIsNotAPatternJunction) {
  cv::Mat sk = Blank();
  cv::line(sk, {20, 5}, {20, 35}, 255);
  cv::line(sk, {5, 20}, {35, 20}, 255);
  const JunctionDetection d = DetectJunction(sk, {20, 20}, pattern::Side::kLeft);
  ASSERT_TRUE(d.is_junction);
  EXPECT_EQ(d.attribute, JunctionAttribute::kCross4);
  EXPECT_FALSE(IsPatternJunction(d.attribute));
}

TEST(JunctionDetect, InvalidInputThrows) {
  EXPECT_THROW(DetectJunction(cv::Mat(), {0, 0}, pattern::Side::kLeft), std::invalid_argument);
  JunctionParams bad;
  bad.max_radius = 0;
  EXPECT_THROW(DetectJunction(Blank(), {5, 5}, pattern::Side::kLeft, bad), std::invalid_argument);
}

// Thesis 5.2.1-5.2.2: line 0 found by the moving line, followed through its
// gaps with the scan areas, each gap sealed.
TEST(ReferenceLine, GapsAreSealedAlongLineZero) {
  testing::SyntheticBrickParams params;
  testing::SyntheticBrick b = testing::DrawSyntheticBrick(params);
  // Gaps within the thesis's 15x15 scan area (up to 7 px).
  testing::EraseLineBetween(b, 0, -3.25, -2.8);  // about 6 px
  testing::EraseLineBetween(b, 0, 5.2, 5.45);    // about 3 px
  cv::Mat sk = b.skeleton.clone();
  ReferenceLine line;
  std::string why;
  ASSERT_TRUE(TraceReferenceLine(sk, params.side, {}, &line, &why)) << why;
  EXPECT_EQ(line.fills.size(), 2u);
  // From the top row of the pattern to its bottom row, on line 0.
  EXPECT_NEAR(line.start().y, b.Map(0, params.first_row - 0.45).y, 2.0);
  EXPECT_NEAR(line.stop().y, b.Map(0, params.last_row + 0.45).y, 2.0);
  for (const cv::Point& p : line.pixels) {
    const double v = (p.y - params.centre_y) / params.row_spacing;
    EXPECT_NEAR(p.x, b.Map(0, v).x, 2.0) << p;
  }
  // Every pixel of the traced line is set in the sealed skeleton.
  for (const cv::Point& p : line.pixels) ASSERT_NE(sk.at<uchar>(p), 0) << p;
}

TEST(ReferenceLine, EmptyFrameHasNone) {
  cv::Mat sk = cv::Mat::zeros(100, 100, CV_8UC1);
  ReferenceLine line;
  std::string why;
  EXPECT_FALSE(TraceReferenceLine(sk, pattern::Side::kLeft, {}, &line, &why));
  EXPECT_FALSE(why.empty());
}

}  // namespace
}  // namespace bsls::interpretation
