#include "bsls/interpretation/interpreter.h"

#include <gtest/gtest.h>

#include "bsls/testing/label_evaluation.h"
#include "bsls/testing/synthetic_brick.h"

namespace bsls::interpretation {
namespace {

using testing::DrawSyntheticBrick;
using testing::PointLabel;
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

testing::LabelScore InterpretAndScore(const SyntheticBrick& b, InterpretationResult* result = nullptr) {
  InterpretationResult r = Interpret(b.skeleton, b.params.side, b.params.spec);
  EXPECT_TRUE(r.ok) << r.error;
  const auto score = testing::ScoreLabels(TruthOf(b), Decoded(r), kMatchReach);
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
  const cv::Point2d l0 = b.Map(0, 0), l1 = b.Map(1, 0);
  const int cut = cvRound((l0.x + l1.x) / 2 + 3);
  b.skeleton.colRange(cut, b.skeleton.cols).setTo(0);
  const InterpretationResult r = Interpret(b.skeleton, params.side, params.spec);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("not line 0"), std::string::npos) << r.error;
}

}  // namespace
}  // namespace bsls::interpretation
