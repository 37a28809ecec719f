#include "bsls/interpretation/interpreter.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bsls/simulator/evaluation.h"
#include "bsls/testing/synthetic_brick.h"

namespace bsls::interpretation {
namespace {

using simulator::PointLabel;
using testing::DrawSyntheticBrick;
using testing::SyntheticBrick;
using testing::SyntheticBrickParams;

constexpr double kMatchReach = 2.5;  // px between a decoded and a true junction

std::vector<PointLabel> TruthOf(const SyntheticBrick& b) {
  std::vector<PointLabel> out;
  for (const auto& j : b.junctions) out.push_back({j.p, j.v, j.position});
  return out;
}

std::vector<PointLabel> Decoded(const InterpretationResult& r) {
  std::vector<PointLabel> out;
  for (const auto& j : r.labelling.junctions) out.push_back({j.p, j.v, j.position});
  return out;
}

simulator::LabelScore InterpretAndScore(const SyntheticBrick& b,
                                        InterpretationResult* result = nullptr) {
  InterpretationResult r = Interpret(b.skeleton, b.params.side, b.params.spec);
  EXPECT_TRUE(r.ok) << r.error;
  const auto score = simulator::ScoreLabels(TruthOf(b), Decoded(r), kMatchReach);
  if (result) *result = std::move(r);
  return score;
}

class CleanBrick : public ::testing::TestWithParam<pattern::Side> {};

TEST_P(CleanBrick, EveryJunctionLabelled) {
  SyntheticBrickParams params;
  params.side = GetParam();
  if (params.side == pattern::Side::kRight) params.line0_x = 511 - params.line0_x;
  const SyntheticBrick b = DrawSyntheticBrick(params);
  InterpretationResult r;
  const auto score = InterpretAndScore(b, &r);
  EXPECT_EQ(score.found, score.truth) << score.Summary();
  EXPECT_EQ(score.Wrong(), 0) << score.Summary();
  EXPECT_EQ(score.unmatched, 0) << score.Summary();
  EXPECT_EQ(score.v_offset % 2, 0);
  EXPECT_TRUE(r.repairs.empty());
  ASSERT_EQ(static_cast<int>(r.labelling.lines.size()), params.visible_lines);
  for (const auto& line : r.labelling.lines) EXPECT_GT(line.pixels.size(), 300u) << line.p;
}

INSTANTIATE_TEST_SUITE_P(BothSides, CleanBrick,
                         ::testing::Values(pattern::Side::kLeft, pattern::Side::kRight));

// Segments on the image's first row: their T-junctions' upper strokes are
// cut off by the edge, leaving corners; the frame around the skeleton lets
// corner extension (5.2.3.3) give them their stubs back.
TEST(Interpreter, JunctionsOnTheImageEdgeAreLabelled) {
  SyntheticBrickParams params;
  params.tilt = 0.0;
  const SyntheticBrick full = DrawSyntheticBrick(params);
  const int top = cvRound(full.Map(0, -15).y) - 1;  // row v = -15 lands on image row 1
  SyntheticBrick b = full;
  b.skeleton = full.skeleton.rowRange(top, full.skeleton.rows).clone();
  b.junctions.clear();
  int on_edge = 0;
  for (auto j : full.junctions) {
    j.position.y -= top;
    if (j.position.y < 0.5) continue;
    on_edge += j.position.y < 2;
    b.junctions.push_back(j);
  }
  ASSERT_GE(on_edge, 10);
  const auto score = InterpretAndScore(b);
  EXPECT_EQ(score.found, score.truth) << score.Summary();
  EXPECT_EQ(score.Wrong(), 0) << score.Summary();

  InterpretationParams no_frame;
  no_frame.frame_margin = 0;
  const InterpretationResult bare = Interpret(b.skeleton, params.side, params.spec, no_frame);
  ASSERT_TRUE(bare.ok) << bare.error;
  const auto without = simulator::ScoreLabels(TruthOf(b), Decoded(bare), kMatchReach);
  EXPECT_LT(without.found, score.found) << "the edge should cost junctions without the frame";
}

TEST(Interpreter, NoReferenceLineIsReportedNotGuessed) {
  cv::Mat empty = cv::Mat::zeros(256, 256, CV_8UC1);
  const InterpretationResult r = Interpret(empty, pattern::Side::kLeft, {});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("reference line"), std::string::npos) << r.error;
}

TEST(Interpreter, LineOneMistakenForLineZeroIsRejected) {
  // Cut line 0 away: the right-most line now carries corresponding junctions.
  SyntheticBrickParams params;
  SyntheticBrick b = DrawSyntheticBrick(params);
  testing::CutAwayLineZero(b);
  const InterpretationResult r = Interpret(b.skeleton, params.side, params.spec);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("not line 0"), std::string::npos) << r.error;
}

}  // namespace
}  // namespace bsls::interpretation

// ---------------------------------------------------------------------------
// Thesis Table 5.5 and section 5.1.4.8: one test per class of discontinuity
// and per overlap case, each cut into a clean brick skeleton; the repair must
// bring back every junction with its right label.

namespace bsls::interpretation {
namespace {

struct DefectCase {
  const char* name;
  void (*cut)(SyntheticBrick&);
  LoopClass expected_class;
};

void OneLineBreak(SyntheticBrick& b) { testing::EraseLineBetween(b, 3, 0.3, 0.7); }
void OneSegmentBreak(SyntheticBrick& b) { testing::EraseSegmentMiddle(b, 3, 3, 0.35); }
void DoubleBreak(SyntheticBrick& b) {
  // Figure 5.34 (a): line 4 broken above and below junction (4, 2).
  testing::EraseLineBetween(b, 4, 1.3, 1.7);
  testing::EraseLineBetween(b, 4, 2.3, 2.7);
}
void MissingCorrespondingJunction(SyntheticBrick& b) {
  // Figure 5.35 (a): (5, 2) is corresponding; its segment comes from line 4.
  testing::EraseDisk(b.skeleton, b.Map(5, 2), 4.0);
}
void MissingDirectJunction(SyntheticBrick& b) {
  // Figure 5.35 (b): (5, 1) is direct; its segment goes to line 6.
  testing::EraseDisk(b.skeleton, b.Map(5, 1), 4.0);
}
void TwoMissingJunctions(SyntheticBrick& b) {
  // Figure 5.36: the segment (5, 1)-(6, 1) with both its junctions gone.
  testing::EraseDisk(b.skeleton, b.Map(5, 1), 4.0);
  testing::EraseDisk(b.skeleton, b.Map(6, 1), 4.0);
  testing::EraseSegmentMiddle(b, 5, 1, 1.0);
}
void LargeArea(SyntheticBrick& b) {
  // Figure 5.38: a hole over several lines and rows.
  const cv::Point2d c = b.Map(7.5, 2.5);
  b.skeleton(cv::Rect(cvRound(c.x) - 16, cvRound(c.y) - 16, 32, 32)).setTo(0);
}

constexpr DefectCase kDefects[] = {
    {"one_line_break", OneLineBreak, LoopClass::kOneDiscontinuity},
    {"one_segment_break", OneSegmentBreak, LoopClass::kOneDiscontinuity},
    {"double_break", DoubleBreak, LoopClass::kDoubleDiscontinuity},
    {"missing_corresponding_junction", MissingCorrespondingJunction, LoopClass::kMissingJunction},
    {"missing_direct_junction", MissingDirectJunction, LoopClass::kMissingJunction},
    {"two_missing_junctions", TwoMissingJunctions, LoopClass::kTwoMissingJunctions},
    {"large_area", LargeArea, LoopClass::kLargeArea},
};

// Readable names in test listings.
void PrintTo(const DefectCase& c, std::ostream* os) { *os << c.name; }

class Table55 : public ::testing::TestWithParam<DefectCase> {};

TEST_P(Table55, RepairRestoresEveryJunctionWithItsLabel) {
  const DefectCase& c = GetParam();
  SyntheticBrickParams params;
  SyntheticBrick b = DrawSyntheticBrick(params);
  c.cut(b);
  InterpretationResult r;
  const auto score = InterpretAndScore(b, &r);
  std::string classes;
  for (const auto& [cls, n] : r.loop_classes)
    classes += std::string(ToString(cls)) + "=" + std::to_string(n) + " ";
  EXPECT_GE(r.loop_classes[c.expected_class], 1) << c.name << ": " << classes;
  EXPECT_FALSE(r.repairs.empty()) << c.name;
  EXPECT_EQ(score.found, score.truth) << c.name << ": " << score.Summary();
  EXPECT_EQ(score.Wrong(), 0) << c.name << ": " << score.Summary();
}

INSTANTIATE_TEST_SUITE_P(Classes, Table55, ::testing::ValuesIn(kDefects),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

// Overlaps happen where lines crowd together (thesis: the side of the nose),
// so these cases use a brick with lines 8 px apart and rows 20 px apart.
SyntheticBrickParams Crowded() {
  SyntheticBrickParams params;
  params.line_pitch = 8.0;
  params.row_spacing = 20.0;
  params.first_row = -10;
  params.last_row = 10;
  params.visible_lines = 20;
  return params;
}

void DrawPolyline(cv::Mat& sk, const std::vector<cv::Point2d>& pts) {
  for (size_t i = 1; i < pts.size(); ++i)
    cv::line(sk, cv::Point(cvRound(pts[i - 1].x), cvRound(pts[i - 1].y)),
             cv::Point(cvRound(pts[i].x), cvRound(pts[i].y)), 255, 1, cv::LINE_8);
}

void OverlapCrossing(SyntheticBrick& b) {
  // Figure 5.39 (a): the lower part of broken line 7 runs up across line 8,
  // making a crossing point of four lines (a_t = 4) and an end beyond it.
  testing::EraseLineBetween(b, 7, 0.25, 0.75);
  DrawPolyline(b.skeleton, {b.Map(7, 0.75), b.Map(8.6, 0.45)});
}
void OverlapTouching(SyntheticBrick& b) {
  // Figure 5.39 (b): line 7 bows over and touches line 8 between two rows;
  // the touching point is a crossing of three lines (a_t = 3), not a junction.
  testing::EraseLineBetween(b, 7, 0.2, 0.8);
  DrawPolyline(b.skeleton, {b.Map(7, 0.2), b.Map(8, 0.5), b.Map(7, 0.8)});
}

constexpr DefectCase kOverlaps[] = {
    {"overlap_crossing", OverlapCrossing, LoopClass::kOverlap},
    {"overlap_touching", OverlapTouching, LoopClass::kOverlap},
};

class Overlap : public ::testing::TestWithParam<DefectCase> {};

TEST_P(Overlap, LinesCrossingKeepEveryJunctionLabel) {
  const DefectCase& c = GetParam();
  SyntheticBrick b = DrawSyntheticBrick(Crowded());
  c.cut(b);
  InterpretationResult r;
  const auto score = InterpretAndScore(b, &r);
  if (const char* dir = std::getenv("BSLS_DEBUG_DIR")) {
    cv::imwrite(std::string(dir) + "/" + c.name + "_in.png", b.skeleton);
    cv::imwrite(std::string(dir) + "/" + c.name + "_out.png", r.skeleton);
  }
  int overlaps = 0;
  for (const auto& [cls, n] : r.loop_classes)
    if (cls == LoopClass::kOverlap || cls == LoopClass::kIncomplete) overlaps += n;
  EXPECT_GE(overlaps, 1) << c.name;
  EXPECT_EQ(score.found, score.truth) << c.name << ": " << score.Summary();
  EXPECT_EQ(score.Wrong(), 0) << c.name << ": " << score.Summary();
}

INSTANTIATE_TEST_SUITE_P(Cases, Overlap, ::testing::ValuesIn(kOverlaps),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

}  // namespace
}  // namespace bsls::interpretation
