#include "bsls/interpretation/ridge_tracks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "bsls/testing/synthetic_brick.h"

namespace bsls::interpretation {
namespace {

using extraction::RidgePoint;
using extraction::RidgePoints;
using testing::DrawSyntheticBrick;
using testing::RenderGrey;
using testing::SyntheticBrick;
using testing::SyntheticBrickParams;

constexpr double kJunctionReach = 2.5;  // px between a network junction and the true one

// Ridge points from (x, y) pairs given in raster order.
RidgePoints Points(int rows, const std::vector<std::pair<float, int>>& at) {
  RidgePoints out;
  for (const auto& [x, y] : at) out.points.push_back({x, y, 50});
  out.row_start.assign(rows + 1, 0);
  int row = 0;
  for (size_t i = 0; i < out.points.size(); ++i)
    while (row <= out.points[i].y) out.row_start[row++] = static_cast<int>(i);
  while (row <= rows) out.row_start[row++] = static_cast<int>(out.points.size());
  return out;
}

TrackNetwork NetworkOf(const cv::Mat& grey, pattern::Side side, const TrackParams& params = {}) {
  cv::Mat s;
  cv::GaussianBlur(grey, s, cv::Size(0, 0), 1.0, 1.0, cv::BORDER_REPLICATE);
  return BuildTrackNetwork(extraction::FindRidgePoints(s), extraction::FindColumnRidgePoints(s),
                           side, params);
}

TEST(RidgeTracks, PointsLinkRowToRowWithinTheStep) {
  // A line leaning 1 px per row, one jumping 3 px at row 4, and a short one.
  std::vector<std::pair<float, int>> at;
  for (int y = 0; y < 8; ++y) {
    at.push_back({10.0f + y, y});
    at.push_back({40.0f + (y >= 4 ? 3.0f : 0.0f), y});
    if (y < 2) at.push_back({70.0f, y});
  }
  std::sort(at.begin(), at.end(), [](auto a, auto b) {
    return a.second != b.second ? a.second < b.second : a.first < b.first;
  });
  const RidgePoints points = Points(8, at);
  std::vector<int> track_of;
  const std::vector<Track> tracks = LinkTracks(points, {}, &track_of);
  ASSERT_EQ(tracks.size(),
            3u);  // the leaning line and the jumping one's two halves; not the short one
  EXPECT_EQ(tracks[0].points.size(), 8u);
  EXPECT_EQ(tracks[1].points.size(), 4u);
  EXPECT_EQ(tracks[2].points.size(), 4u);
  for (size_t k = 1; k < tracks[0].points.size(); ++k)
    EXPECT_EQ(points.points[tracks[0].points[k]].y, points.points[tracks[0].points[k - 1]].y + 1);
  int unlinked = 0;
  for (int t : track_of) unlinked += t < 0;
  EXPECT_EQ(unlinked, 2);  // the short line's two points
}

TEST(RidgeTracks, TheNearerClaimantKeepsAPoint) {
  // Two points of row 0 both nearest to the one point of row 1.
  const RidgePoints points =
      Points(4, {{10.0f, 0}, {11.0f, 0}, {10.8f, 1}, {10.8f, 2}, {10.8f, 3}});
  TrackParams params;
  params.min_track = 1;
  std::vector<int> track_of;
  const std::vector<Track> tracks = LinkTracks(points, params, &track_of);
  ASSERT_EQ(tracks.size(), 2u);
  EXPECT_EQ(track_of[1], track_of[2]);  // x 11.0 is 0.2 away, x 10.0 0.8
  EXPECT_NE(track_of[0], track_of[2]);
}

class CleanBrickTracks : public ::testing::TestWithParam<pattern::Side> {};

TEST_P(CleanBrickTracks, EveryJunctionFoundWithItsKind) {
  SyntheticBrickParams params;
  params.side = GetParam();
  if (params.side == pattern::Side::kRight) params.line0_x = 511 - params.line0_x;
  const SyntheticBrick b = DrawSyntheticBrick(params);
  const TrackNetwork net = NetworkOf(RenderGrey(b), params.side);
  for (const testing::TruthJunction& t : b.junctions) {
    const TrackJunction* best = nullptr;
    for (const TrackJunction& j : net.junctions)
      if (cv::norm(j.position - t.position) <= kJunctionReach &&
          (!best || cv::norm(j.position - t.position) < cv::norm(best->position - t.position)))
        best = &j;
    ASSERT_NE(best, nullptr) << "no junction at (" << t.p << ", " << t.v << ")";
    EXPECT_EQ(best->kind, t.kind) << "(" << t.p << ", " << t.v << ")";
  }
  // Every junction sits on its line track in order down it.
  for (size_t line = 0; line < net.lines.size(); ++line)
    for (size_t k = 1; k < net.junctions_on_line[line].size(); ++k)
      EXPECT_LE(net.junctions[net.junctions_on_line[line][k - 1]].position.y,
                net.junctions[net.junctions_on_line[line][k]].position.y);
}

INSTANTIATE_TEST_SUITE_P(BothSides, CleanBrickTracks,
                         ::testing::Values(pattern::Side::kLeft, pattern::Side::kRight),
                         [](const auto& test_info) {
                           return std::string(pattern::ToString(test_info.param));
                         });

TEST(RidgeTracks, AGapInALineIsBridged) {
  SyntheticBrickParams params;
  SyntheticBrick b = DrawSyntheticBrick(params);
  testing::EraseLineBetween(b, 3, 0.15, 0.85);  // 9 px of 13 between two junctions
  const TrackNetwork net = NetworkOf(RenderGrey(b), params.side);
  // The track of line 3 above the gap continues in the one below it.
  auto track_at = [&](cv::Point2d at) {
    const int y = cvRound(at.y);
    for (int i = net.rows.row_start[y]; i < net.rows.row_start[y + 1]; ++i)
      if (std::abs(net.rows.points[i].x - at.x) < 2) return net.line_of_point[i];
    return -1;
  };
  const int upper = track_at(b.Map(3, 0.1)), lower = track_at(b.Map(3, 0.9));
  ASSERT_GE(upper, 0);
  ASSERT_GE(lower, 0);
  ASSERT_NE(upper, lower) << "no gap";
  EXPECT_EQ(net.line_below[upper], lower);
  EXPECT_EQ(net.line_above[lower], upper);
}

TEST(RidgeTracks, ASegmentTrackClimbingAlongASlantedLineIsCut) {
  // Column points (x: row, y: column): a segment at row 10 over columns
  // 0-9, then a line slanted 45 degrees from (10, 10) to (21, 21), then the
  // next row's segment at row 22 over columns 22-31; and a segment that
  // climbs 0.3 rows per column over 20 columns, which stays whole.
  std::vector<std::pair<float, int>> at;
  for (int c = 0; c < 32; ++c) {
    at.push_back({c < 10 ? 10.0f : c < 22 ? static_cast<float>(c) : 22.0f, c});
    if (c < 20) at.push_back({40.0f + 0.3f * c, c});
  }
  std::sort(at.begin(), at.end(), [](auto a, auto b) {
    return a.second != b.second ? a.second < b.second : a.first < b.first;
  });
  const RidgePoints columns = Points(32, at);
  const std::vector<Track> linked = LinkTracks(columns, {});
  ASSERT_EQ(linked.size(), 2u);
  const std::vector<Track> cut = CutSteepStretches(columns, linked, {});
  ASSERT_EQ(cut.size(), 3u);
  std::vector<std::tuple<float, int, int>> spans;  // (first row, first column, last column)
  for (const Track& t : cut)
    spans.emplace_back(columns.points[t.points.front()].x, columns.points[t.points.front()].y,
                       columns.points[t.points.back()].y);
  std::sort(spans.begin(), spans.end());
  const auto& [first_row, first_from, first_to] = spans[0];  // the first segment
  EXPECT_EQ(first_row, 10.0f);
  EXPECT_EQ(first_from, 0);
  EXPECT_GE(first_to, 5);  // its steep end cut away
  EXPECT_LE(first_to, 9);
  const auto& [next_row, next_from, next_to] = spans[1];  // the next row's segment
  EXPECT_EQ(next_row, 22.0f);
  EXPECT_GE(next_from, 22);
  EXPECT_LE(next_from, 26);
  EXPECT_EQ(next_to, 31);
  const auto& [gentle_row, gentle_from, gentle_to] = spans[2];  // whole
  EXPECT_EQ(gentle_row, 40.0f);
  EXPECT_EQ(gentle_from, 0);
  EXPECT_EQ(gentle_to, 19);
}

TEST(RidgeTracks, ASegmentWhoseEndsMeetOneLineMakesNoJunction) {
  // Lines at x = 20 and x = 35 over rows 0-29; a speck of light across the
  // first at row 10 (columns 18-22), a segment between both at row 20.
  std::vector<std::pair<float, int>> line_points;
  for (int y = 0; y < 30; ++y) {
    line_points.push_back({20.0f, y});
    line_points.push_back({35.0f, y});
  }
  std::vector<std::pair<float, int>> column_points;  // (row, column)
  for (int c = 18; c <= 22; ++c) column_points.push_back({10.0f, c});
  for (int c = 21; c <= 34; ++c) column_points.push_back({20.0f, c});
  std::sort(column_points.begin(), column_points.end(), [](auto a, auto b) {
    return a.second != b.second ? a.second < b.second : a.first < b.first;
  });
  const TrackNetwork net =
      BuildTrackNetwork(Points(30, line_points), Points(40, column_points), pattern::Side::kLeft);
  ASSERT_EQ(net.junctions.size(), 2u);  // the segment's two ends, none of the speck's
  for (const TrackJunction& j : net.junctions) EXPECT_NEAR(j.position.y, 20.0, 1.0);
  EXPECT_NE(net.junctions[0].line, net.junctions[1].line);
}

// Ridge points of a line that leans more and more as it descends: straight
// down x = 20 over rows 0-9, leaning 0.8 px per row to row 19 (about 39
// degrees, within the row tracks' step), then, in the column ridge points
// only, 2 px per row (63 degrees, past the step) over columns 29-40; where
// `below`, it goes on as a row track again from row 26 at x = 42.
struct LeaningLine {
  std::vector<std::pair<float, int>> rows, columns;  // (x, row); (row, column)
  explicit LeaningLine(bool below) {
    for (int y = 0; y < 20; ++y) rows.push_back({20.0f + (y < 10 ? 0.0f : 0.8f * (y - 9)), y});
    for (int c = 29; c <= 40; ++c) columns.push_back({19.0f + (c - 28) / 2.0f, c});
    if (below)
      for (int y = 26; y < 46; ++y) rows.push_back({42.0f, y});
  }
  TrackNetwork Build() const {
    return BuildTrackNetwork(Points(46, rows), Points(48, columns), pattern::Side::kLeft);
  }
};

TEST(RidgeTracks, ALineLeaningPastTheStepGoesOnThroughTheColumnPoints) {
  const TrackNetwork net = LeaningLine(true).Build();
  ASSERT_EQ(net.lines.size(), 2u);
  const int upper = net.rows.points[net.lines[0].points.front()].y == 0 ? 0 : 1;
  const int lower = 1 - upper;
  EXPECT_EQ(net.line_below[upper], lower);
  EXPECT_EQ(net.line_above[lower], upper);
  // Its path runs from the upper track's end through the column points to
  // the lower track's start, by increasing row.
  const std::vector<cv::Point2d>& path = net.path_below[upper];
  ASSERT_GE(path.size(), 8u);
  EXPECT_NEAR(path.front().x, 28.0, 1e-6);
  EXPECT_NEAR(path.back().x, 42.0, 1e-6);
  for (size_t k = 1; k < path.size(); ++k) EXPECT_GT(path[k].y, path[k - 1].y);
  // The piece followed is no segment: it makes no junction.
  EXPECT_TRUE(net.junctions.empty());
}

TEST(RidgeTracks, ALineLeaningPastTheStepToItsEndGetsATail) {
  const TrackNetwork net = LeaningLine(false).Build();
  ASSERT_EQ(net.lines.size(), 1u);
  EXPECT_EQ(net.line_below[0], -1);
  const std::vector<cv::Point2d>& tail = net.path_below[0];
  ASSERT_GE(tail.size(), 8u);
  EXPECT_NEAR(tail.back().x, 40.0, 1e-6);
  EXPECT_NEAR(tail.back().y, 25.0, 1e-6);
}

TEST(RidgeTracks, ASegmentLeavingALeaningLinesEndIsNotFollowed) {
  // The same line, but what leaves its end in the column points runs along
  // row 19: a segment (the frame's segments run along the rows), not the
  // line leaning on.
  LeaningLine line(false);
  line.columns.clear();
  for (int c = 29; c <= 40; ++c) line.columns.push_back({19.0f, c});
  const TrackNetwork net = line.Build();
  EXPECT_TRUE(net.path_below[0].empty());
  EXPECT_EQ(net.segments.size(), 1u);
}

TEST(RidgeTracks, InvalidParamsAreRejected) {
  TrackParams bad;
  bad.max_step = 0;
  EXPECT_THROW(BuildTrackNetwork({}, {}, pattern::Side::kLeft, bad), std::invalid_argument);
  bad = {};
  bad.bridge_rows = 0;
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("bridge_rows"), std::string::npos);
  bad = {};
  bad.steep_columns = 1;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("steep_columns"), std::string::npos);
}

}  // namespace
}  // namespace bsls::interpretation
