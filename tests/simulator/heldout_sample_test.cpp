// A small fixed sample of the held-out set (random_scene.h) through the
// default decoder: the first kSampleFrames held-out seeds whose image is at
// most kMaxSampleSize px (so that the sample runs in seconds). The full
// 200-frame figures are bench/decoder/heldout_report's (docs/heldout.md).
// Nothing is tuned on these frames; the thresholds say what the decoder of
// the day does on them, and what it must never do.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "bsls/decoder/decoder.h"
#include "bsls/simulator/evaluation.h"
#include "bsls/simulator/random_scene.h"
#include "bsls/simulator/renderer.h"
#include "test_options.h"

namespace bsls::simulator {
namespace {

constexpr int kSampleFrames = 6;
constexpr int kMaxSampleSize = 800;  // px, the larger image side
constexpr double kMatchReach = 2.5;  // px, as the report
constexpr int kLineZeroJunctions = 3;

std::vector<std::uint32_t> SampleSeeds() {
  std::vector<std::uint32_t> seeds;
  for (int i = 0; static_cast<int>(seeds.size()) < kSampleFrames; ++i) {
    const RandomSceneDraw d = DrawRandomScene(SeedOf(SeedSet::kHeldOut, i));
    if (std::max(d.width, d.height) <= kMaxSampleSize) seeds.push_back(d.seed);
  }
  return seeds;
}

class HeldOutSample : public ::testing::TestWithParam<int> {};

TEST_P(HeldOutSample, DecoderNeverMislabelsALine) {
  const std::uint32_t seed = SampleSeeds()[GetParam()];
  const RandomScene random = MakeRandomScene(
      seed, {kDataDir / "canonical_face_model.obj", kDataDir / "stanford_bunny.json"});
  SCOPED_TRACE(random.draw.Describe());
  const Frame frame = Renderer(random.scene, random.render).Render();
  const decoder::DecodeResult r = decoder::Decode(frame.image, random.scene.side);
  const std::vector<PointLabel> truth = VisibleJunctions(frame.truth);
  const bool line_zero_visible =
      std::count_if(truth.begin(), truth.end(), [](const PointLabel& j) { return j.p == 0; }) >=
      kLineZeroJunctions;
  if (!line_zero_visible) {
    // Contracts section 2: without its reference line a frame is refused.
    EXPECT_FALSE(r.ok);
    return;
  }
  std::vector<PointLabel> decoded;
  for (const auto& j : r.junctions) decoded.push_back({j.p, j.q, j.position});
  const LabelScore score = ScoreLabels(truth, decoded, kMatchReach);
  SCOPED_TRACE(score.Summary());
  // What the decoder must never do: give a junction the wrong line.
  EXPECT_EQ(score.wrong_p, 0);
  // TODO(issue 25): the figures the decoder of 2026-11-27 meets; tighten them
  // as it improves (the target: no frame refused whose line 0 shows,
  // no wrong q, and recall near the thesis scenes' 0.99).
  EXPECT_TRUE(r.ok) << r.error;
  EXPECT_LE(score.wrong_v, 0);
  EXPECT_GE(score.Recall(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(FirstSmallSeeds, HeldOutSample, ::testing::Range(0, kSampleFrames));

}  // namespace
}  // namespace bsls::simulator
