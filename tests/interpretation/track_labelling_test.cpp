#include "bsls/interpretation/track_labelling.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "bsls/simulator/evaluation.h"
#include "bsls/testing/synthetic_brick.h"
#include "label_votes.h"

namespace bsls::interpretation {
namespace {

using simulator::PointLabel;
using testing::DrawSyntheticBrick;
using testing::RenderGrey;
using testing::SyntheticBrick;
using testing::SyntheticBrickParams;

constexpr double kMatchReach = 2.5;  // px between a labelled and a true junction

struct Labelled {
  TrackNetwork net;
  TrackLabels labels;
};

Labelled Label(const cv::Mat& grey, pattern::Side side) {
  cv::Mat s;
  cv::GaussianBlur(grey, s, cv::Size(0, 0), 1.0, 1.0, cv::BORDER_REPLICATE);
  Labelled out;
  out.net =
      BuildTrackNetwork(extraction::FindRidgePoints(s), extraction::FindColumnRidgePoints(s), side);
  out.labels = LabelTracks(out.net, side, {});
  return out;
}

simulator::LabelScore Score(const SyntheticBrick& b, const Labelled& l) {
  std::vector<PointLabel> truth, decoded;
  for (const auto& j : b.junctions) truth.push_back({j.p, j.v, j.position});
  for (size_t j = 0; j < l.net.junctions.size(); ++j)
    if (l.labels.p[j] != kUnlabelled)
      decoded.push_back({l.labels.p[j], l.labels.v[j], l.net.junctions[j].position});
  return simulator::ScoreLabels(truth, decoded, kMatchReach);
}

class CleanBrickLabels : public ::testing::TestWithParam<pattern::Side> {};

TEST_P(CleanBrickLabels, EveryJunctionLabelledAndEveryLineNumbered) {
  SyntheticBrickParams params;
  params.side = GetParam();
  if (params.side == pattern::Side::kRight) params.line0_x = 511 - params.line0_x;
  const SyntheticBrick b = DrawSyntheticBrick(params);
  const Labelled l = Label(RenderGrey(b), params.side);
  ASSERT_TRUE(l.labels.ok) << l.labels.error;
  const auto score = Score(b, l);
  EXPECT_EQ(score.found, score.truth) << score.Summary();
  EXPECT_EQ(score.Wrong(), 0) << score.Summary();
  EXPECT_EQ(score.v_offset % 2, 0);
  // Line 0's junction nearest the centre row is v = 0 (thesis point O):
  // the brick's v = 0 row is at its centre.
  EXPECT_EQ(score.v_offset, 0);
  std::set<int> lines;
  for (int p : l.labels.line_p)
    if (p >= 0) lines.insert(p);
  EXPECT_EQ(static_cast<int>(lines.size()), params.visible_lines);
}

INSTANTIATE_TEST_SUITE_P(BothSides, CleanBrickLabels,
                         ::testing::Values(pattern::Side::kLeft, pattern::Side::kRight),
                         [](const auto& test_info) {
                           return std::string(pattern::ToString(test_info.param));
                         });

// Thesis Table 5.5: the discontinuities that leave every junction in sight.
// A break in a line or a segment takes one link away; the label comes
// through the brick's other links (no drawing needed), and where a line's
// two pieces bridge a gap, its junctions are placed on them.
struct Cut {
  const char* name;
  void (*cut)(SyntheticBrick&);
};

constexpr Cut kCuts[] = {
    {"one_line_break", [](SyntheticBrick& b) { testing::EraseLineBetween(b, 3, 0.3, 0.7); }},
    {"one_segment_break", [](SyntheticBrick& b) { testing::EraseSegmentMiddle(b, 3, 3, 0.35); }},
    {"double_break",
     [](SyntheticBrick& b) {
       testing::EraseLineBetween(b, 4, 1.3, 1.7);
       testing::EraseLineBetween(b, 4, 2.3, 2.7);
     }},
    {"line_zero_break", [](SyntheticBrick& b) { testing::EraseLineBetween(b, 0, 0.4, 1.6); }},
};

class Discontinuity : public ::testing::TestWithParam<Cut> {};

TEST_P(Discontinuity, EveryJunctionStillLabelled) {
  SyntheticBrickParams params;
  SyntheticBrick b = DrawSyntheticBrick(params);
  GetParam().cut(b);
  const Labelled l = Label(RenderGrey(b), params.side);
  ASSERT_TRUE(l.labels.ok) << l.labels.error;
  const auto score = Score(b, l);
  EXPECT_EQ(score.found, score.truth) << score.Summary();
  EXPECT_EQ(score.Wrong(), 0) << score.Summary();
}

INSTANTIATE_TEST_SUITE_P(Table55, Discontinuity, ::testing::ValuesIn(kCuts),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

TEST(TrackLabelling, AHoleLosesOnlyWhatItCovers) {
  // Figure 5.38: a large area over several lines and rows. The junctions in
  // it are gone; every other one keeps its label.
  SyntheticBrickParams params;
  SyntheticBrick b = DrawSyntheticBrick(params);
  const cv::Point2d c = b.Map(7.5, 2.5);
  const cv::Rect hole(cvRound(c.x) - 16, cvRound(c.y) - 16, 32, 32);
  b.skeleton(hole).setTo(0);
  const Labelled l = Label(RenderGrey(b), params.side);
  ASSERT_TRUE(l.labels.ok) << l.labels.error;
  const auto score = Score(b, l);
  EXPECT_EQ(score.Wrong(), 0) << score.Summary();
  const cv::Rect near_hole(hole.x - 4, hole.y - 4, hole.width + 8, hole.height + 8);
  for (const PointLabel& m : score.missed)
    EXPECT_TRUE(near_hole.contains(cv::Point(cvRound(m.position.x), cvRound(m.position.y))))
        << "missed (" << m.p << ", " << m.v << ") away from the hole";
}

TEST(TrackLabelling, AStrayJunctionOnLineZeroShiftsNoRow) {
  // A stub of a segment leaving line 0 half a row below its junction
  // (0, 2) (a segment's end caught at a fold): a direct junction too close
  // to the real one to be a row of its own. Counted as one, it would shift
  // every row below it by two.
  SyntheticBrickParams params;
  SyntheticBrick b = DrawSyntheticBrick(params);
  const cv::Point2d from = b.Map(0, 2.5), to = b.Map(0.6, 2.5);
  cv::line(b.skeleton, cv::Point(cvRound(from.x), cvRound(from.y)),
           cv::Point(cvRound(to.x), cvRound(to.y)), 255, 1, cv::LINE_8);
  const Labelled l = Label(RenderGrey(b), params.side);
  ASSERT_TRUE(l.labels.ok) << l.labels.error;
  const auto score = Score(b, l);
  EXPECT_EQ(score.Wrong(), 0) << score.Summary();
  EXPECT_GE(score.found, score.truth - 2) << score.Summary();
}

TEST(TrackLabelling, NoReferenceLineIsReportedNotGuessed) {
  const Labelled blank = Label(cv::Mat(256, 256, CV_8UC1, cv::Scalar(20)), pattern::Side::kLeft);
  EXPECT_FALSE(blank.labels.ok);
  EXPECT_NE(blank.labels.error.find("reference line"), std::string::npos) << blank.labels.error;
}

TEST(TrackLabelling, LineOneMistakenForLineZeroIsRejected) {
  // Cut line 0 away: the right-most line now carries the stubs of the
  // segments that came from line 0, i.e. corresponding junctions.
  SyntheticBrickParams params;
  SyntheticBrick b = DrawSyntheticBrick(params);
  testing::CutAwayLineZero(b);
  const Labelled l = Label(RenderGrey(b), params.side);
  EXPECT_FALSE(l.labels.ok);
  EXPECT_NE(l.labels.error.find("line 0"), std::string::npos) << l.labels.error;
}

// Consistency along the line (label_votes.h): junctions down one line
// labelled p 0, 0, 2, 2, 0 cannot all be right; the run of 2 between the
// runs of 0 is dropped (held-out seed 100900: three junctions of line 0 at
// the ball's shadow were labelled p 2 through a segment into the ball).
TEST(LineRuns, ARunBetweenTwoRunsOfAnotherPIsDropped) {
  constexpr int U = kUnlabelled;
  std::vector<int> p = {0, 0, 2, U, 2, 0, 5, 5};
  std::vector<int> v = {-4, -2, 0, U, 4, 6, 0, 2};
  const std::vector<std::vector<int>> lines = {{0, 1, 2, 3, 4, 5}, {6, 7}};
  EXPECT_EQ(internal::DropRunsBetweenOneP(lines, &p, &v, U), 2);
  EXPECT_EQ(p, (std::vector<int>{0, 0, U, U, U, 0, 5, 5}));
  EXPECT_EQ(v, (std::vector<int>{-4, -2, U, U, U, 6, 0, 2}));
}

// A line may cross onto another surface once (the base plane beside an
// object, both parts labelled right): its p changes and stays changed, and
// nothing is dropped; nor at either end of the line.
TEST(LineRuns, APChangingOnceOrAtAnEndIsKept) {
  std::vector<int> p = {0, 0, 0, 3, 3, 1, 4, 4};
  std::vector<int> v = {0, 2, 4, 6, 8, 0, 2, 4};
  const std::vector<int> p_before = p, v_before = v;
  EXPECT_EQ(internal::DropRunsBetweenOneP({{0, 1, 2, 3, 4}, {5, 6, 7}}, &p, &v, kUnlabelled), 0);
  EXPECT_EQ(p, p_before);
  EXPECT_EQ(v, v_before);
}

TEST(TrackLabelling, InvalidParamsAreRejected) {
  TrackLabellingParams bad;
  bad.max_row_miss = 0.7;
  EXPECT_THROW(LabelTracks({}, pattern::Side::kLeft, {}, bad), std::invalid_argument);
  bad = {};
  bad.reference_choice = -1;
  EXPECT_THROW(LabelTracks({}, pattern::Side::kLeft, {}, bad), std::invalid_argument);
  bad = {};
  bad.min_whole_links = -1;
  EXPECT_THROW(LabelTracks({}, pattern::Side::kLeft, {}, bad), std::invalid_argument);
}

// A clean brick offers one chain of line-0 candidates: the first is line 0,
// and asking for another labels nothing rather than guessing.
TEST(TrackLabelling, OnlyTheChainsOfCandidatesThereAreAreTaken) {
  SyntheticBrickParams params;
  const SyntheticBrick b = DrawSyntheticBrick(params);
  Labelled l = Label(RenderGrey(b), params.side);
  ASSERT_TRUE(l.labels.ok) << l.labels.error;
  EXPECT_EQ(l.labels.reference_choices, 1);
  TrackLabellingParams second;
  second.reference_choice = 1;
  const TrackLabels other = LabelTracks(l.net, params.side, {}, second);
  EXPECT_FALSE(other.ok);
  EXPECT_NE(other.error.find("no candidate 1"), std::string::npos) << other.error;
}

}  // namespace
}  // namespace bsls::interpretation
