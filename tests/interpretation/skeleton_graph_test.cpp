#include "bsls/interpretation/skeleton_graph.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "bsls/interpretation/junction_network.h"
#include "bsls/interpretation/loop_trace.h"
#include "bsls/testing/synthetic_brick.h"

namespace bsls::interpretation {
namespace {

TEST(SkeletonGraph, TJunctionHasThreeBranchesInAnticlockwiseOrder) {
  cv::Mat sk = cv::Mat::zeros(40, 40, CV_8UC1);
  cv::line(sk, {20, 5}, {20, 35}, 255);
  cv::line(sk, {20, 20}, {5, 20}, 255);
  const SkeletonGraph g = SkeletonGraph::Build(sk);
  int junctions = 0, ends = 0;
  for (const auto& n : g.nodes()) (n.kind == NodeKind::kJunction ? junctions : ends)++;
  EXPECT_EQ(junctions, 1);
  EXPECT_EQ(ends, 3);
  EXPECT_EQ(g.edges().size(), 3u);
  // A tree has one face, walked round all three arms.
  const auto faces = g.Faces();
  ASSERT_EQ(faces.size(), 1u);
  EXPECT_EQ(faces[0].size(), 6u);

  const JunctionNetwork net(g, pattern::Side::kLeft);
  for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n) {
    if (g.nodes()[n].kind != NodeKind::kJunction) continue;
    // Segment to the left on the left side: direct.
    EXPECT_EQ(net.role(n).attribute, JunctionAttribute::kDirect);
  }
  const JunctionNetwork right(g, pattern::Side::kRight);
  for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n) {
    if (g.nodes()[n].kind == NodeKind::kJunction) {
      EXPECT_EQ(right.role(n).attribute, JunctionAttribute::kCorresponding);
    }
  }
}

// The skirt of a lump facing away from the projector: the line comes down at
// ~37 degrees from vertical and leaves at ~72 degrees, nearly as flat as its
// segment (~8 degrees from horizontal). The flatter branch is the segment and
// the line is followed through the junction both ways (it was lost there
// with a 70 degree limit on a line's lean, and with it the rows below).
TEST(JunctionNetwork, ASteepLineIsFollowedPastASegmentNearlyAsFlat) {
  cv::Mat sk = cv::Mat::zeros(100, 100, CV_8UC1);
  const cv::Point junction{50, 50};
  cv::line(sk, junction, {68, 26}, 255);  // up, 37 degrees from vertical
  cv::line(sk, junction, {22, 59}, 255);  // down, 72 degrees from vertical
  cv::line(sk, junction, {80, 54}, 255);  // the segment, 8 degrees from horizontal
  const SkeletonGraph g = SkeletonGraph::Build(sk);
  const JunctionNetwork net(g, pattern::Side::kLeft);
  int junctions = 0;
  for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n) {
    if (g.nodes()[n].kind != NodeKind::kJunction) continue;
    ++junctions;
    const auto down = net.AlongLine(n, true), up = net.AlongLine(n, false);
    ASSERT_TRUE(down.has_value());
    ASSERT_TRUE(up.has_value());
    EXPECT_LT(g.nodes()[down->target].centre.x, 30.0);
    EXPECT_GT(g.nodes()[up->target].centre.y, 20.0);
    EXPECT_LT(g.nodes()[up->target].centre.y, 32.0);
    const auto across = net.AcrossSegment(n);
    ASSERT_TRUE(across.has_value());
    EXPECT_GT(g.nodes()[across->target].centre.x, 75.0);
    // Segment to the right on the left side: corresponding.
    EXPECT_EQ(net.role(n).attribute, JunctionAttribute::kCorresponding);
  }
  EXPECT_EQ(junctions, 1);
}

// Where a fold squeezes two lines to 3 px apart (the nasolabial fold of the
// lesion frame), the segment between them is two pixels long and every pixel
// of the H has three or more neighbours: one cluster of four branches, read
// as a crossing, and both junctions were lost. Split, each is a T of the
// pattern: a line up and down and the segment to the other.
TEST(SkeletonGraph, TwoJunctionsJoinedByAShortSegmentAreTwoNodes) {
  for (const int gap : {3, 4, 6}) {
    SCOPED_TRACE(gap);
    cv::Mat sk = cv::Mat::zeros(60, 60, CV_8UC1);
    const int left = 25, right = left + gap;
    cv::line(sk, {left, 5}, {left, 55}, 255);
    cv::line(sk, {right, 5}, {right, 55}, 255);
    cv::line(sk, {left, 30}, {right, 30}, 255);
    const SkeletonGraph g = SkeletonGraph::Build(sk);
    const JunctionNetwork net(g, pattern::Side::kLeft);
    std::vector<int> junctions;
    for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n)
      if (g.nodes()[n].kind == NodeKind::kJunction) junctions.push_back(n);
    ASSERT_EQ(junctions.size(), 2u);
    for (int n : junctions) {
      EXPECT_EQ(g.Degree(n), 3);
      EXPECT_TRUE(net.IsPatternJunction(n));
      const bool is_left = g.nodes()[n].centre.x < left + gap / 2.0;
      // Left side: a segment to the right is corresponding, to the left direct.
      EXPECT_EQ(net.role(n).attribute,
                is_left ? JunctionAttribute::kCorresponding : JunctionAttribute::kDirect);
      const auto across = net.AcrossSegment(n);
      ASSERT_TRUE(across.has_value());
      EXPECT_TRUE(across->consistent);
      EXPECT_NE(across->target, n);
      for (const bool down : {false, true}) {
        const auto along = net.AlongLine(n, down);
        ASSERT_TRUE(along.has_value());
        EXPECT_NEAR(g.nodes()[along->target].centre.x, is_left ? left : right, 0.5);
      }
    }
  }
}

// At the nasolabial fold line 3 comes out from behind the fold beside line 5
// and its end merges into line 5's strand: a Y whose short way on to line
// 5's next junction (3 px) read as its segment, so line 5 was walked into
// line 3 below the Y and its own rows were lost. The junction at the end
// of that short way has a segment of its own and takes the edge for its
// line: the Y is a crossing point on line 5, which goes on through it.
TEST(JunctionNetwork, ALineMergingAtAFoldIsNotTakenForASegment) {
  cv::Mat sk = cv::Mat::zeros(90, 60, CV_8UC1);
  const cv::Point y_node{30, 40}, junction{26, 44};
  cv::line(sk, {30, 5}, y_node, 255);     // line 5 from above
  cv::line(sk, y_node, junction, 255);    // its short way on (3 px between)
  cv::line(sk, junction, {26, 85}, 255);  // line 5 below its junction
  cv::line(sk, junction, {8, 44}, 255);   // that junction's segment
  cv::line(sk, y_node, {42, 80}, 255);    // line 3, come out from behind the fold
  const SkeletonGraph g = SkeletonGraph::Build(sk);
  const JunctionNetwork net(g, pattern::Side::kLeft);
  auto node_near = [&](cv::Point p) {
    for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n)
      if (cv::norm(g.nodes()[n].centre - cv::Point2d(p)) < 1.5) return n;
    return -1;
  };
  const int y = node_near(y_node), j = node_near(junction), top = node_near({30, 5});
  const int emerging = node_near({42, 80});
  ASSERT_GE(y, 0);
  ASSERT_GE(j, 0);
  ASSERT_GE(top, 0);
  ASSERT_GE(emerging, 0);
  EXPECT_FALSE(net.IsPatternJunction(y));
  EXPECT_TRUE(net.IsPatternJunction(j));
  // Line 5 runs from the top through the Y to its junction and on.
  const auto into_y = net.AlongLine(top, true);
  ASSERT_TRUE(into_y.has_value());
  EXPECT_EQ(into_y->target, y);
  EXPECT_TRUE(into_y->consistent);
  const auto on = net.AlongLine(y, true);
  ASSERT_TRUE(on.has_value());
  EXPECT_EQ(on->target, j);
  EXPECT_TRUE(on->consistent);
  // Line 3 ends at the Y.
  const auto up = net.AlongLine(emerging, false);
  ASSERT_TRUE(up.has_value());
  EXPECT_EQ(up->target, y);
  EXPECT_FALSE(up->consistent);

  // With no merge edge allowed the Y is the junction it looked like.
  JunctionParams strict;
  strict.max_merge_edge = 0;
  const JunctionNetwork as_before(g, pattern::Side::kLeft, strict);
  EXPECT_TRUE(as_before.IsPatternJunction(y));
}

// Two lines crossing (thesis 5.1.4.8) are not taken for such an H: the
// branch pixels of an X lie above one another, so its node (or the two nodes
// of a shallow crossing, joined along the shared run) stays on the crossing.
TEST(SkeletonGraph, LinesCrossingAreNotSplitSideways) {
  for (const int half_width : {4, 10, 25}) {
    SCOPED_TRACE(half_width);
    cv::Mat sk = cv::Mat::zeros(60, 60, CV_8UC1);
    cv::line(sk, {30 - half_width, 5}, {30 + half_width, 55}, 255);
    cv::line(sk, {30 + half_width, 5}, {30 - half_width, 55}, 255);
    const SkeletonGraph g = SkeletonGraph::Build(sk);
    int junctions = 0, branches = 0;
    for (int n = 0; n < static_cast<int>(g.nodes().size()); ++n)
      if (g.nodes()[n].kind == NodeKind::kJunction) {
        ++junctions;
        branches += g.Degree(n);
        EXPECT_NEAR(g.nodes()[n].centre.x, 30.0, 1.0);
      }
    EXPECT_GE(junctions, 1);
    EXPECT_LE(junctions, 2);
    EXPECT_EQ(branches, junctions == 1 ? 4 : 6);
  }
}

TEST(SkeletonGraph, ClosedRingWithoutNodesGetsAnAnchor) {
  cv::Mat sk = cv::Mat::zeros(40, 40, CV_8UC1);
  cv::rectangle(sk, {10, 10}, {30, 25}, 255);
  const SkeletonGraph g = SkeletonGraph::Build(sk);
  ASSERT_EQ(g.nodes().size(), 1u);
  EXPECT_EQ(g.nodes()[0].kind, NodeKind::kAnchor);
  const auto faces = g.Faces();
  ASSERT_EQ(faces.size(), 2u);  // inside and outside
  const double a0 = g.SignedArea2(faces[0]), a1 = g.SignedArea2(faces[1]);
  EXPECT_LT(a0 * a1, 0.0);  // walked in opposite senses
}

TEST(LoopTrace, CleanBrickGivesCompleteLoopsAndOneBoundary) {
  testing::SyntheticBrickParams params;
  const testing::SyntheticBrick brick = testing::DrawSyntheticBrick(params);
  const SkeletonGraph g = SkeletonGraph::Build(brick.skeleton);
  const JunctionNetwork net(g, params.side);
  const auto loops = TraceLoops(net);
  std::map<LoopClass, int> classes;
  for (const auto& l : loops) ++classes[l.cls];
  EXPECT_EQ(classes[LoopClass::kBoundary], 1);
  // Bricks between lines p and p+1: about (rows/2) per column.
  EXPECT_GT(classes[LoopClass::kComplete], 150);
  EXPECT_EQ(classes[LoopClass::kOverlap], 0);
  // Every junction is a pattern junction with the right kind.
  int checked = 0;
  for (const auto& t : brick.junctions) {
    const int n = g.NodeAt(cv::Point(cvRound(t.position.x), cvRound(t.position.y)));
    if (n < 0 || g.nodes()[n].kind != NodeKind::kJunction) continue;
    ++checked;
    const auto a = net.role(n).attribute;
    ASSERT_TRUE(a.has_value());
    EXPECT_EQ(*a == JunctionAttribute::kDirect, t.kind == pattern::JunctionKind::kDirect)
        << "p=" << t.p << " v=" << t.v;
  }
  EXPECT_GT(checked, static_cast<int>(brick.junctions.size() * 9 / 10));
}

}  // namespace
}  // namespace bsls::interpretation
