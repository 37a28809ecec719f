// The decoder on the thesis's lesion frame (issue: single-shot decoding):
// crowded and steep lines on the lesions' walls, scored against the
// simulator's ground truth. Labelled `accuracy`: figures on a full frame,
// left to the RelWithDebInfo stage (the decoder's code runs under the
// sanitizers in decoder_test).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <utility>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "decoder_evaluation.h"

namespace bsls::decoder::test {
namespace {

// The thesis's lesions (Tables 7.3-7.4: a lump on the cheek, cavities above
// the eyebrow and on the other cheek) on the face, left side, rendered once.
class LesionFace : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    simulator::ThesisSceneOptions options;
    options.face_lesions = {{.centre_xy_mm = {-42.0, -32.0},
                             .height_mm = 15.0,
                             .radius_mm = 30.0,
                             .top_radius_mm = 12.0},
                            {.centre_xy_mm = {-28.0, 50.0},
                             .height_mm = -15.0,
                             .radius_mm = 28.0,
                             .top_radius_mm = 11.0},
                            {.centre_xy_mm = {42.0, -30.0},
                             .height_mm = -10.0,
                             .radius_mm = 16.0,
                             .top_radius_mm = 7.0}};
    simulator::RenderParams render;
    render.noise_sigma = kNoiseSigma;
    render.seed = 5;
    render.supersampling = 1;  // the lesions' surface is slow to trace; one ray per pixel
    frame_ = new simulator::Frame(simulator::Render(
        simulator::ThesisScene(Side::kLeft, SurfaceKind::kFace, options), render));
    result_ = new DecodeResult(Decode(frame_->image, Side::kLeft));
    skeleton_ = new DecodeResult(Decode(frame_->image, Side::kLeft, SkeletonChainParams()));
  }
  static void TearDownTestSuite() {
    delete skeleton_;
    delete result_;
    delete frame_;
  }
  // The decoded points of lines first_p..last_p in rows first_y..last_y that
  // have a true crossing in their row, and their RMS distance from it (px).
  static std::pair<int, double> ScoreStretch(const DecodeResult& r, int first_p, int last_p,
                                             int first_y, int last_y) {
    std::map<int, std::map<int, double>> truth;  // p -> row -> x
    for (const simulator::LinePoints& line : simulator::TruthLines(frame_->truth))
      for (const cv::Point2d& q : line.points)
        truth[line.p][static_cast<int>(std::lround(q.y))] = q.x;
    int points = 0;
    double sum_sq = 0.0;
    for (const DecodedLine& line : r.lines) {
      if (line.p < first_p || line.p > last_p) continue;
      for (const cv::Point2d& q : line.points) {
        const int y = static_cast<int>(std::lround(q.y));
        if (y < first_y || y > last_y || !truth[line.p].contains(y)) continue;
        ++points;
        sum_sq += std::pow(q.x - truth[line.p][y], 2);
      }
    }
    return {points, std::sqrt(sum_sq / std::max(points, 1))};
  }

  // The decodes by the default chain (the track chain) and by the skeleton
  // chain: the outcomes below hold for both.
  static std::vector<std::pair<const char*, const DecodeResult*>> BothChains() {
    return {{"default chain", result_}, {"skeleton chain", skeleton_}};
  }
  static std::vector<std::pair<const char*, const DecodeResult*>> SkeletonChainOnly() {
    return {{"skeleton chain", skeleton_}};
  }

  static inline simulator::Frame* frame_ = nullptr;
  static inline DecodeResult* result_ = nullptr;    // the default chain's
  static inline DecodeResult* skeleton_ = nullptr;  // the skeleton chain's
};

// Below the nasolabial fold lines 4-6 run 3-8 px apart (rows 355-385), so
// the segments between them are 2-6 px long and each pair of T-junctions
// they join fell into one skeleton cluster of four branches, read as a
// crossing: (4,8), (5,8), (5,9) and (6,9) were lost and lines 4 and 5 left
// unlabelled there. Each such H is split into its two junctions
// (interpretation::SkeletonGraph::Build).
TEST_F(LesionFace, JunctionsJoinedByShortSegmentsBelowTheFoldAreFound) {
  // The skeleton chain's: the track chain proves no label below the nose
  // on this frame (TrackChainLabelsOnlyWhatItProves).
  for (const auto& [chain, decoded_by] : SkeletonChainOnly()) {
    SCOPED_TRACE(chain);
    const DecodeResult& r = *decoded_by;
    ASSERT_TRUE(r.ok) << r.error;
    const cv::Rect2d fold(295.0, 355.0, 35.0, 30.0);
    std::vector<simulator::PointLabel> truth, decoded;
    for (const simulator::PointLabel& l : simulator::VisibleJunctions(frame_->truth))
      if (fold.contains(l.position)) truth.push_back(l);
    for (const auto& j : r.junctions) decoded.push_back({j.p, j.q, j.position});
    const simulator::LabelScore score = simulator::ScoreLabels(truth, decoded, kMatchReach);
    EXPECT_GE(score.truth, 6) << score.Summary();
    EXPECT_EQ(score.found, score.truth) << score.Summary();
    EXPECT_EQ(score.Wrong(), 0) << score.Summary();
  }
}

// Above the hidden stretch of the nasolabial fold line 3 comes out from
// behind the fold beside line 5 (row 349) and its end merges into line 5's
// strand: a Y that read as a junction of line 5 with line 3 below it, so
// line 5 lost its label from its junction (5,6) down to (5,7), and with its
// strand unlabelled the joint fits of lines 3-4 beside it failed. The
// junction at the end of the Y's short way on takes that edge for its line
// (interpretation::JunctionParams::max_merge_edge); the Y is a crossing.
TEST_F(LesionFace, ALineComingOutFromBehindTheFoldLeavesItsNeighbourWhole) {
  DecodeParams before = SkeletonChainParams();
  before.interpretation.junction.max_merge_edge = 0;
  const DecodeResult as_before = Decode(frame_->image, Side::kLeft, before);
  ASSERT_TRUE(skeleton_->ok && as_before.ok);
  // Lines 3-5 in rows 336-348.
  auto score = [](const DecodeResult& r) { return ScoreStretch(r, 3, 5, 336, 348); };
  const auto [now_points, now_rms] = score(*skeleton_);
  const auto [before_points, before_rms] = score(as_before);
  std::printf(
      "[ figures  ] lines 3-5, rows 336-348: %d points, RMS %.3f px; as before %d, RMS %.3f px\n",
      now_points, now_rms, before_points, before_rms);
  // 14 points at 0.202 px against 8 at 0.266 px (2026-11-26).
  EXPECT_GE(now_points, before_points + 5);
  EXPECT_LE(now_rms, before_rms);
  const Evaluation now = Evaluate(*frame_, *skeleton_), then = Evaluate(*frame_, as_before);
  EXPECT_EQ(now.all.Wrong(), 0);
  EXPECT_GE(now.all.found, then.all.found);
  EXPECT_LE(now.line_rms, then.line_rms + 0.002);
}

// The forehead cavity's wall crowds lines 3-5 within a few pixels, where a
// line's chain can cross onto a neighbour's strand: a line walked from its
// junctions must stop before a junction of another line, or it takes the
// neighbour's strand with it and its own centres are lost (before, on this
// frame: 1 wrong p, 94.0 % found, line centre RMS 0.47 px, line 3 with 110
// points).
TEST_F(LesionFace, CrowdedLinesKeepTheirOwnStrands) {
  for (const auto& [chain, decoded_by] : BothChains()) {
    SCOPED_TRACE(chain);
    const DecodeResult& r = *decoded_by;
    ASSERT_TRUE(r.ok) << r.error;
    const Evaluation e = Evaluate(*frame_, r);
    EXPECT_EQ(e.all.Wrong(), 0) << e.all.Summary();
    if (decoded_by != skeleton_) continue;  // the track chain's: TrackChainLabelsOnlyWhatItProves
    EXPECT_GE(e.all.Recall(), 0.95) << e.all.Summary();
    EXPECT_LE(e.line_rms, 0.15) << "points " << e.line_points;
    for (const DecodedLine& line : r.lines) {
      if (line.p >= 3 && line.p <= 5) {
        EXPECT_GT(line.points.size(), 250u) << "line " << line.p;
      }
    }
  }
}

// The track chain reports only labels its junction graph proves
// (docs/decoding.md, "Labels: proven, or reported unlabelled"). On this
// frame line 0 breaks at the nose's tip and the rows below the nose meet
// the rows above through few links: what no two links (or line 0's own
// seeds) join is reported unlabelled, none of it wrong. 0.796 of the
// junctions are labelled today (0.746 before lines leaning past the row
// tracks were followed through the column points); the goal is the
// skeleton chain's 0.95 (with a calibration, the epipolar candidates will
// join what the image alone cannot).
TEST_F(LesionFace, TrackChainLabelsOnlyWhatItProves) {
  ASSERT_TRUE(result_->ok) << result_->error;
  const Evaluation e = Evaluate(*frame_, *result_);
  EXPECT_EQ(e.all.Wrong(), 0) << e.all.Summary();
  EXPECT_GE(e.all.Recall(), 0.78) << e.all.Summary();
  EXPECT_GE(result_->unlabelled.size(), 80u);
  // 0.22 px today: line tracks that run on below the last proven junction
  // into the unlabelled part keep their centres (no junction there cuts them).
  EXPECT_LE(e.line_rms, 0.25) << "points " << e.line_points;
}

// On the lump's skirts lines lean 45-65 degrees. A segment's light biases
// the wide row profiles of a steep line over many rows on the side where the
// line runs along the segment (the acute angle), not on the side where it
// leans away: those rows are measured (but left out of the junction fits).
// Skipping them on both sides, as before, kept 4050 points at 0.130 px RMS
// on this frame.
TEST_F(LesionFace, SteepLinesKeepTheRowsLeaningAwayFromASegment) {
  for (const auto& [chain, decoded_by] : SkeletonChainOnly()) {
    SCOPED_TRACE(chain);
    ASSERT_TRUE(decoded_by->ok) << decoded_by->error;
    const Evaluation e = Evaluate(*frame_, *decoded_by);
    EXPECT_GE(e.line_points, 4100);
    EXPECT_LE(e.line_rms, 0.13) << "points " << e.line_points;
  }
}

// On the lump's lower skirt lines lean 50-60 degrees, and the rows beside
// each of their segments are skipped over a clearance that grows with the
// slope. A parabola through such a stretch was not trusted to refill them;
// where it holds at least two measured rows on each side within 0.05 px RMS
// (steep_fill_residual) it is, and those refills are as good as the
// measured rows.
TEST_F(LesionFace, SteepStretchesAreRefilledWhereTheirFitHoldsClosely) {
  DecodeParams never = SkeletonChainParams();
  never.steep_fill_residual = 0.0;
  const DecodeResult unfilled = Decode(frame_->image, Side::kLeft, never);
  ASSERT_TRUE(skeleton_->ok && unfilled.ok);
  // The refilled points: in the decode, not in the one that never refills
  // steep stretches; scored against the true centre in their row.
  std::map<int, std::map<int, double>> truth, before;  // p -> row -> x
  for (const simulator::LinePoints& line : simulator::TruthLines(frame_->truth))
    for (const cv::Point2d& q : line.points)
      truth[line.p][static_cast<int>(std::lround(q.y))] = q.x;
  for (const DecodedLine& line : unfilled.lines)
    for (const cv::Point2d& q : line.points)
      before[line.p][static_cast<int>(std::lround(q.y))] = q.x;
  int refilled = 0;
  double sum_sq = 0.0;
  for (const DecodedLine& line : skeleton_->lines)
    for (const cv::Point2d& q : line.points) {
      const int y = static_cast<int>(std::lround(q.y));
      if (before[line.p].contains(y)) continue;
      ASSERT_TRUE(truth[line.p].contains(y)) << "p " << line.p << " row " << y;
      ++refilled;
      sum_sq += std::pow(q.x - truth[line.p][y], 2);
    }
  const double rms = std::sqrt(sum_sq / std::max(refilled, 1));
  const Evaluation with = Evaluate(*frame_, *skeleton_), without = Evaluate(*frame_, unfilled);
  std::printf(
      "[ figures  ] steep stretches refilled: %d points, RMS %.3f px; whole frame %d points, "
      "RMS %.4f px (without: %d, %.4f px)\n",
      refilled, rms, with.line_points, with.line_rms, without.line_points, without.line_rms);
  // 2026-11-26: 164 points at 0.069 px on this frame; the whole frame 4321
  // points at 0.1132 px against 4157 at 0.1146 px.
  EXPECT_GE(refilled, 40);
  EXPECT_LE(rms, 0.12);
  EXPECT_LE(with.line_rms, without.line_rms + 0.002);
  // Only points are added; junctions and labels are the same.
  ASSERT_NO_FATAL_FAILURE(ExpectSameJunctions(*skeleton_, unfilled));
}

// Where the lump's edge meets the nasolabial fold, lines 3-5 crowd to 4-7 px
// apart (rows 300-335 of this frame, before 3 and 4 pass behind the fold).
// Measured one by one, a line there is pulled by its neighbour's light, and
// skipped where the neighbour's skeleton lies 2-4 px beside it as if it were
// a segment; the rows of each crowd fitted jointly (crowd_distance,
// extraction::StripeCentresInRow) keep more of them, and more accurately.
TEST_F(LesionFace, LinesCrowdedAtAFoldAreMeasuredTogether) {
  DecodeParams alone = SkeletonChainParams();
  alone.crowd_distance = 0.0;
  const DecodeResult one_by_one = Decode(frame_->image, Side::kLeft, alone);
  ASSERT_TRUE(skeleton_->ok && one_by_one.ok);
  // Lines 4 and 5 in rows 300-335.
  auto score = [](const DecodeResult& r) { return ScoreStretch(r, 4, 5, 300, 335); };
  const auto [joint_points, joint_rms] = score(*skeleton_);
  const auto [alone_points, alone_rms] = score(one_by_one);
  std::printf(
      "[ figures  ] lines 4-5, rows 300-335: jointly %d points, RMS %.3f px; one by one %d, RMS "
      "%.3f px\n",
      joint_points, joint_rms, alone_points, alone_rms);
  // 34 points at 0.028 px against 28 at 0.091 px (2026-11-26).
  EXPECT_GE(joint_points, alone_points + 4);
  EXPECT_LE(joint_rms, 0.5 * alone_rms);
  // The whole frame no worse.
  const Evaluation joint = Evaluate(*frame_, *skeleton_), apart = Evaluate(*frame_, one_by_one);
  std::printf(
      "[ figures  ] whole frame: jointly %d points, RMS %.4f px; one by one %d, RMS %.4f px\n",
      joint.line_points, joint.line_rms, apart.line_points, apart.line_rms);
  EXPECT_GE(joint.line_points, apart.line_points);
  EXPECT_LE(joint.line_rms, apart.line_rms + 0.005);
  EXPECT_EQ(joint.all.Wrong(), 0);
}

}  // namespace
}  // namespace bsls::decoder::test
