// A small fixed sample of the held-out set (random_scene.h) through the
// default decoder: the first kSampleFrames held-out seeds whose image is at
// most kMaxSampleSize px on its larger side (so that the sample runs in
// seconds). The full 200-frame figures are bench/decoder/heldout_report's
// (docs/heldout.md). Nothing is tuned on these frames.
//
// What the decoder must never do is asserted outright: label a junction with
// the wrong line p, or label a frame whose line 0 is hidden (contracts
// section 2). The rest are the figures the decoder of 2026-11-27 meets on the
// sample, to be tightened towards the target as it improves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/simulator/evaluation.h"
#include "bsls/simulator/random_scene.h"
#include "bsls/simulator/renderer.h"
#include "test_options.h"

namespace bsls::simulator {
namespace {

constexpr int kSampleFrames = 6;
constexpr int kMaxSampleSize = 800;     // px, the larger image side
constexpr double kMatchReach = 2.5;     // px, as the report
constexpr int kLineZeroJunctions = 3;   // visible junctions on line 0 that make it visible
constexpr double kBasePlaneBand = 0.5;  // mm: junctions this close to z = 0 are on the base plane

// Figures of the decoder of 2026-11-27 on the sample (seeds 100000 bunny,
// 100004-100006 faces, 100011 ramp, 100013 cylinder), measured: no wrong p,
// no wrong q, 2 refusals with line 0 visible (the bunny and the cylinder),
// recall 0.633 on the objects and 0.341 on all visible junctions (the faces'
// base plane beyond the face is not labelled at all). The thresholds keep a
// little room below them. The target: no refusal while line 0
// shows, no wrong q, recall >= 0.95 on the objects and on the base plane
// around them alike.
constexpr int kMaxWrongRefusals = 2;
constexpr int kMaxWrongQ = 0;
constexpr double kMinObjectRecall = 0.60;
constexpr double kMinRecall = 0.32;

std::vector<std::uint32_t> SampleSeeds() {
  std::vector<std::uint32_t> seeds;
  for (int i = 0; static_cast<int>(seeds.size()) < kSampleFrames; ++i) {
    const RandomSceneDraw d = DrawRandomScene(SeedOf(SeedSet::kHeldOut, i));
    if (std::max(d.width, d.height) <= kMaxSampleSize) seeds.push_back(d.seed);
  }
  return seeds;
}

int Right(const LabelScore& s) { return s.found - s.Wrong(); }

// The decoder's labelled junctions, as the scoring takes them.
std::vector<PointLabel> DecodedLabels(const decoder::DecodeResult& r) {
  std::vector<PointLabel> decoded;
  for (const auto& j : r.junctions) decoded.push_back({j.p, j.q, j.position});
  return decoded;
}

// The random scene of `seed`, rendered.
Frame RenderSeed(std::uint32_t seed, RandomScene* random) {
  *random = MakeRandomScene(
      seed, {kDataDir / "canonical_face_model.obj", kDataDir / "stanford_bunny.json"});
  return Renderer(random->scene, random->render).Render();
}

TEST(HeldOutSample, DecoderNeverMislabelsALineAndMeetsTodaysFigures) {
  int wrong_refusals = 0, wrong_q = 0, truth = 0, right = 0, object_truth = 0, object_right = 0;
  for (const std::uint32_t seed : SampleSeeds()) {
    RandomScene random;
    const Frame frame = RenderSeed(seed, &random);
    SCOPED_TRACE(random.draw.Describe());
    const decoder::DecodeResult r = decoder::Decode(frame.image, random.scene.side);
    const std::vector<PointLabel> visible = VisibleJunctions(frame.truth);
    const bool line_zero_visible =
        std::count_if(visible.begin(), visible.end(),
                      [](const PointLabel& j) { return j.p == 0; }) >= kLineZeroJunctions;
    if (!line_zero_visible) {
      // Contracts section 2: without its reference line a frame is refused.
      EXPECT_FALSE(r.ok);
      continue;
    }
    const std::vector<PointLabel> decoded = DecodedLabels(r);
    std::vector<PointLabel> on_object;
    for (const TruthJunction& j : frame.truth.junctions)
      if (j.visible &&
          (random.draw.object == RandomObject::kPlane || std::abs(j.world.z()) >= kBasePlaneBand))
        on_object.push_back({j.p, j.v, {j.image.x(), j.image.y()}});
    const LabelScore all = ScoreLabels(visible, decoded, kMatchReach);
    const LabelScore object = ScoreLabels(on_object, decoded, kMatchReach);
    // What the decoder must never do: give a junction the wrong line.
    EXPECT_EQ(all.wrong_p, 0) << all.Summary();
    wrong_refusals += !r.ok;
    wrong_q += all.wrong_v;
    truth += all.truth;
    right += Right(all);
    object_truth += object.truth;
    object_right += Right(object);
    std::printf("seed %u %s: %s%s\n", seed, std::string(ToString(random.draw.object)).c_str(),
                r.ok ? "" : "refused; ", all.Summary().substr(0, 120).c_str());
  }
  ASSERT_GT(truth, 0);
  ASSERT_GT(object_truth, 0);
  const double recall = static_cast<double>(right) / truth;
  const double object_recall = static_cast<double>(object_right) / object_truth;
  std::printf("sample: %d wrong refusals, %d wrong q, recall %.3f, on the objects %.3f\n",
              wrong_refusals, wrong_q, recall, object_recall);
  EXPECT_LE(wrong_refusals, kMaxWrongRefusals);
  EXPECT_LE(wrong_q, kMaxWrongQ);
  EXPECT_GE(object_recall, kMinObjectRecall);
  EXPECT_GE(recall, kMinRecall);
}

// The labels the decoder (with `params`) gives held-out seed `seed`, scored
// against its truth; a refused frame fails the test.
LabelScore DecodeSeed(std::uint32_t seed, const decoder::DecodeParams& params = {}) {
  RandomScene random;
  const Frame frame = RenderSeed(seed, &random);
  const decoder::DecodeResult r = decoder::Decode(frame.image, random.scene.side, params);
  EXPECT_TRUE(r.ok) << "seed " << seed << ": " << r.error;
  return ScoreLabels(VisibleJunctions(frame.truth), DecodedLabels(r), kMatchReach);
}

// Held-out seed 100900 (a ball, right side; looked at to build the rule, so
// no longer held out): line 0 runs down the edge of the ball's shadow, and
// three of its junctions were labelled p 2 through segments into the ball
// while the line above and below them carried p 0. Consistency along the
// line drops them.
TEST(HeldOutSample, AJunctionRunAgainstItsLineIsNotLabelled) {
  const LabelScore all = DecodeSeed(100900);
  EXPECT_EQ(all.wrong_p, 0) << all.Summary();
  EXPECT_GE(all.Recall(), 0.95) << all.Summary();
}

// Held-out seed 101010 (a cylinder on the base plane, right side; looked at
// to build the rule, so no longer held out): the base plane's lines end on
// the cylinder's lower edge and the cylinder's lines go on from there;
// bridged as gaps in one line, five such steps agreed on joining the base
// plane below to the cylinder 5 lines off (74 wrong p). Steps across gaps
// alone join nothing now (TrackLabellingParams::min_whole_links).
TEST(HeldOutSample, LinesEndingOnAnOccludingEdgeJoinNothingThroughTheirGaps) {
  const LabelScore all = DecodeSeed(101010);
  EXPECT_EQ(all.wrong_p, 0) << all.Summary();
  EXPECT_EQ(all.wrong_v, 0) << all.Summary();
  EXPECT_GE(all.Right(), 130) << all.Summary();  // the cylinder's own, as before

  decoder::DecodeParams before;  // any links, gaps alone included
  before.track_chain.labelling.min_whole_links = 0;
  EXPECT_GT(DecodeSeed(101010, before).wrong_p, 50)
      << "the case this test holds is gone from the frame";
}

// Held-out seed 101366 (a ball, right side, pitch 8.9 px; looked at to
// build the rule, so no longer held out): on the ball's limb, seen nearly
// edge-on, its lines crowd, and bricks closed over lines that were not
// neighbours joined the whole ball to the base plane 4 lines off (180
// wrong p). A brick whose top or bottom segment is abrupt no longer closes
// (TrackLabellingParams::close_abrupt_bricks).
TEST(HeldOutSample, BricksClosedOverACrowdedLimbAreNotTrusted) {
  const LabelScore all = DecodeSeed(101366);
  EXPECT_LE(all.wrong_p, 10) << all.Summary();   // 6 left, joined through other links
  EXPECT_GE(all.Right(), 550) << all.Summary();  // the base plane's, as before

  decoder::DecodeParams before;
  before.track_chain.labelling.close_abrupt_bricks = true;
  EXPECT_GT(DecodeSeed(101366, before).wrong_p, 100)
      << "the case this test holds is gone from the frame";
}

// Held-out seed 100771 (a face turned 18.5 degrees, left side; looked at to
// build the rule, so no longer held out): line 0 hides behind the nose's
// profile over part of its length, where the reference line runs on line
// 1. Its seeds there joined the face's patch while those on line 0 itself
// were left out (their bricks abrupt), and every label came out one line
// low. Those seeds' links place them beyond line 0: the frame is refused.
TEST(HeldOutSample, ALineZeroRunningOnLineOneWhereItHidesIsRefused) {
  RandomScene random;
  const Frame frame = RenderSeed(100771, &random);
  const decoder::DecodeResult r = decoder::Decode(frame.image, random.scene.side, {});
  EXPECT_FALSE(r.ok) << "labelled although its line 0 runs on line 1 in places";
  if (r.ok) {
    const LabelScore all =
        ScoreLabels(VisibleJunctions(frame.truth), DecodedLabels(r), kMatchReach);
    EXPECT_EQ(all.wrong_p, 0) << all.Summary();
  }
}

}  // namespace
}  // namespace bsls::simulator
