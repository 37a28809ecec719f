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

// A T that the frame's top edge cut into an L: line A runs up to the edge,
// the segment along the edge is broken (half its profile is outside the
// frame) and ends free after 8 px. The skeleton lies inside a 4-px empty
// margin, as Interpret gives it.
struct EdgeCorner {
  cv::Mat skeleton = cv::Mat::zeros(64, 64, CV_8UC1);
  cv::Mat mask = cv::Mat::zeros(64, 64, CV_8UC1);
  cv::Rect imaged{4, 4, 56, 56};
  explicit EdgeCorner(int corner_row) {
    cv::line(skeleton, {30, 50}, {30, corner_row}, 255);          // line A, up to the corner
    cv::line(skeleton, {30, corner_row}, {22, corner_row}, 255);  // the segment's piece
    cv::line(skeleton, {30, 40}, {40, 40}, 255);                  // a junction below
    // The stripes: line A's stroke going on up, the segment's along the row.
    cv::rectangle(mask, cv::Rect(29, 0, 3, 52), 255, cv::FILLED);
    cv::rectangle(mask, cv::Rect(10, corner_row - 1, 21, 3), 255, cv::FILLED);
    mask |= skeleton;
  }
};

TEST(CornerExtension, ACornerWhoseLineRunsOutOfTheFrameTakesAShortSegment) {
  EdgeCorner at_edge(4);  // the corner on the first imaged row
  const std::vector<cv::Point> corners = ExtendCorners(
      SkeletonGraph::Build(at_edge.skeleton), {}, at_edge.skeleton, at_edge.mask, at_edge.imaged);
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_NEAR(corners[0].x, 30, 1);
  EXPECT_NEAR(corners[0].y, 4, 1);
  // The stub went into the margin.
  EXPECT_GT(cv::countNonZero(at_edge.skeleton(cv::Rect(29, 0, 3, 4))), 0);
}

TEST(CornerExtension, TheSameShortSegmentInsideTheFrameIsAHook) {
  EdgeCorner inside(20);  // the same shape well inside the frame
  const std::vector<cv::Point> corners = ExtendCorners(SkeletonGraph::Build(inside.skeleton), {},
                                                       inside.skeleton, inside.mask, inside.imaged);
  EXPECT_TRUE(corners.empty());
}

// A line with T-junctions every 13 rows whose segments alternate sides, as
// the brick pattern has them, up to a corner with an 8 px segment (the
// face's outline cut the rest: the forehead's top, the chin). `first_side`:
// the side (+1 right, -1 left) of the segment of the junction nearest the
// corner; `first_row`: that junction's row (the corner is on row 14).
struct PatternCorner {
  cv::Mat skeleton = cv::Mat::zeros(80, 80, CV_8UC1);
  cv::Mat mask = cv::Mat::zeros(80, 80, CV_8UC1);
  PatternCorner(int first_side, int first_row) {
    cv::line(skeleton, {30, 76}, {30, 14}, 255);  // the line, up to the corner
    cv::line(skeleton, {30, 14}, {22, 14}, 255);  // the corner's segment, to the left
    for (int row = first_row, side = first_side; row <= 70; row += 13, side = -side)
      cv::line(skeleton, {30, row}, {30 + 12 * side, row}, 255);
    cv::rectangle(mask, cv::Rect(29, 0, 3, 78), 255, cv::FILLED);  // the line's stroke goes on
    cv::rectangle(mask, cv::Rect(10, 13, 21, 3), 255, cv::FILLED);
    mask |= skeleton;
  }
  std::vector<cv::Point> Extend() {
    return ExtendCorners(SkeletonGraph::Build(skeleton), {}, skeleton, mask);
  }
};

TEST(CornerExtension, ACornerWhereThePatternPutsTheNextJunctionTakesAShortSegment) {
  PatternCorner in_pattern(+1, 27);  // one row pitch below, its segment on the other side
  const std::vector<cv::Point> corners = in_pattern.Extend();
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_NEAR(corners[0].x, 30, 1);
  EXPECT_NEAR(corners[0].y, 14, 1);
  EXPECT_GT(cv::countNonZero(in_pattern.skeleton(cv::Rect(29, 9, 3, 4))), 0);  // the stub
}

TEST(CornerExtension, AShortSegmentOnTheSideOfTheLastJunctionsSegmentIsAHook) {
  PatternCorner same_side(-1, 27);  // the pattern alternates: this one is not a T
  EXPECT_TRUE(same_side.Extend().empty());
}

TEST(CornerExtension, AShortSegmentTwoRowPitchesFromTheLastJunctionIsAHook) {
  PatternCorner far(-1, 40);  // the junction nearest the corner two pitches away
  EXPECT_TRUE(far.Extend().empty());
}

// The chin's bottom row: a line leaning 27 degrees from vertical down to a
// corner where the outline cut it, its 9 px segment leaving on the side the
// pattern puts there (the junction one row pitch above has its segment on
// the other side). Line and segment meet at ~60 degrees, so the stub's first
// pixel beyond the corner touches the segment's first pixel.
struct LeaningPatternCorner {
  cv::Mat skeleton = cv::Mat::zeros(80, 80, CV_8UC1);
  cv::Mat mask = cv::Mat::zeros(80, 80, CV_8UC1);
  static int LineX(int row) { return 30 + (60 - row) / 2; }
  LeaningPatternCorner() {
    cv::line(skeleton, {LineX(4), 4}, {30, 60}, 255);  // the line, down to the corner
    cv::line(skeleton, {30, 60}, {21, 60}, 255);       // the corner's segment, to the left
    for (int row = 47, side = +1; row >= 8; row -= 13, side = -side)
      cv::line(skeleton, {LineX(row), row}, {LineX(row) + 12 * side, row}, 255);
    // The line's stroke goes on below the corner, as the segment's does.
    cv::line(mask, {LineX(0), 0}, {LineX(76), 76}, 255, 3);
    cv::rectangle(mask, cv::Rect(14, 59, 17, 3), 255, cv::FILLED);
    mask |= skeleton;
  }
};

TEST(CornerExtension, ALineMeetingItsSegmentAtASharpAngleWhereThePatternPutsATTakesAStub) {
  LeaningPatternCorner chin;
  const std::vector<cv::Point> corners =
      ExtendCorners(SkeletonGraph::Build(chin.skeleton), {}, chin.skeleton, chin.mask);
  ASSERT_EQ(corners.size(), 1u);
  EXPECT_NEAR(corners[0].x, 30, 1);
  EXPECT_NEAR(corners[0].y, 60, 1);
  // The stub goes on down along the line, below the segment.
  EXPECT_GT(cv::countNonZero(chin.skeleton(cv::Rect(26, 61, 5, 4))), 0);
  const SkeletonGraph g = SkeletonGraph::Build(chin.skeleton);
  const JunctionNetwork net(g, pattern::Side::kLeft);
  int t_junctions = 0;
  for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n)
    if (net.IsPatternJunction(n) && std::abs(g.nodes()[n].centre.y - 60) < 2) ++t_junctions;
  EXPECT_EQ(t_junctions, 1);
}

}  // namespace
}  // namespace bsls::interpretation
