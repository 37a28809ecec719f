#include "bsls/interpretation/corner_extension.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "bsls/interpretation/junction_network.h"

namespace bsls::interpretation {
namespace {

// A brick's top with both stubs cut off: line A up to a corner, the segment
// across, line B down from the second corner, both lines going on to
// junctions below (so the segment ends on lines at both corners).
cv::Mat CutOffBrickTop() {
  cv::Mat sk = cv::Mat::zeros(60, 60, CV_8UC1);
  cv::line(sk, {15, 50}, {15, 20}, 255);  // line A
  cv::line(sk, {15, 20}, {35, 20}, 255);  // top segment
  cv::line(sk, {35, 20}, {35, 50}, 255);  // line B
  cv::line(sk, {15, 40}, {5, 40}, 255);   // segments making junctions below
  cv::line(sk, {35, 45}, {45, 45}, 255);
  return sk;
}

TEST(CornerExtension, BothCutOffCornersBecomeJunctions) {
  cv::Mat sk = CutOffBrickTop();
  const std::vector<cv::Point> corners = ExtendCorners(SkeletonGraph::Build(sk), {}, sk);
  ASSERT_EQ(corners.size(), 2u);
  // Each stub goes on upwards along its line.
  EXPECT_GT(cv::countNonZero(sk(cv::Rect(14, 16, 3, 3))), 0);
  EXPECT_GT(cv::countNonZero(sk(cv::Rect(33, 16, 3, 3))), 0);
  const SkeletonGraph g = SkeletonGraph::Build(sk);
  const JunctionNetwork net(g, pattern::Side::kLeft);
  int t_junctions = 0;
  for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n)
    if (net.IsPatternJunction(n) && std::abs(g.nodes()[n].centre.y - 20) < 2) ++t_junctions;
  EXPECT_EQ(t_junctions, 2);
}

TEST(CornerExtension, NoStubWhereTheMaskShowsNoStroke) {
  cv::Mat sk = CutOffBrickTop();
  const cv::Mat mask = sk.clone();  // the image shows nothing beyond the corners
  const std::vector<cv::Point> corners = ExtendCorners(SkeletonGraph::Build(sk), {}, sk, mask);
  EXPECT_TRUE(corners.empty());
  EXPECT_EQ(cv::countNonZero(sk), cv::countNonZero(mask));
}

TEST(CornerExtension, LineTurningAlongAnOutlineIsLeftAlone) {
  // A line that turns and runs off sideways to a free end (a face's outline).
  cv::Mat sk = cv::Mat::zeros(60, 60, CV_8UC1);
  cv::line(sk, {15, 50}, {15, 20}, 255);
  cv::line(sk, {15, 20}, {50, 20}, 255);
  cv::line(sk, {15, 40}, {5, 40}, 255);
  const std::vector<cv::Point> corners = ExtendCorners(SkeletonGraph::Build(sk), {}, sk);
  EXPECT_TRUE(corners.empty());
}

}  // namespace
}  // namespace bsls::interpretation
