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
