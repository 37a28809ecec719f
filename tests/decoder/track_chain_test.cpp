// The decoder's track chain (DecodeChain::kTracks) against the simulator's
// ground truth: the same targets as the skeleton chain's (decoder_test.cpp).
#include <gtest/gtest.h>

#include <string>

#include <opencv2/core/utility.hpp>

#include "bsls/decoder/decode_output.h"
#include "bsls/decoder/decoder.h"
#include "decoder_evaluation.h"

namespace bsls::decoder::test {
namespace {

DecodeParams TrackChain() {
  DecodeParams params;
  params.chain = DecodeChain::kTracks;
  return params;
}

struct SceneCase {
  SurfaceKind kind;
  Side side;
};

std::string Name(const SceneCase& c) {
  return std::string(simulator::ToString(c.kind)) + "_" + std::string(pattern::ToString(c.side));
}

void PrintTo(const SceneCase& c, std::ostream* os) { *os << Name(c); }

class TrackChainObjects : public ::testing::TestWithParam<SceneCase> {};

// Planes, ramp and ball: every junction, no wrong label.
TEST_P(TrackChainObjects, EveryJunctionRightlyLabelled) {
  const SceneCase c = GetParam();
  const simulator::Frame frame = RenderFrame(c.kind, c.side, 7);
  const DecodeResult r = Decode(frame.image, c.side, TrackChain());
  ASSERT_TRUE(r.ok) << r.error;
  const Evaluation e = Evaluate(frame, r);
  EXPECT_EQ(e.all.found, e.all.truth) << Name(c) << ": " << e.all.Summary();
  EXPECT_EQ(e.all.Wrong(), 0) << Name(c) << ": " << e.all.Summary();
  EXPECT_EQ(e.all.v_offset % 2, 0);
  EXPECT_LE(e.line_rms, 0.1) << Name(c);
  EXPECT_GT(e.line_points, 5000) << Name(c);
}

INSTANTIATE_TEST_SUITE_P(
    Simulated, TrackChainObjects,
    ::testing::Values(SceneCase{SurfaceKind::kPlane, Side::kLeft},
                      SceneCase{SurfaceKind::kPlane, Side::kRight},
                      SceneCase{SurfaceKind::kRamp, Side::kLeft},
                      SceneCase{SurfaceKind::kRamp, Side::kRight},
                      SceneCase{SurfaceKind::kBall, Side::kLeft},
                      SceneCase{SurfaceKind::kBall, Side::kRight}),
    [](const auto& test_info) { return Name(test_info.param); });

class TrackChainFaces : public ::testing::TestWithParam<Side> {};

// Faces with eyebrow patches and noise: no wrong label, line centres within
// 0.15 px RMS, >= 98 % of the lit and visible junctions (seeds 1-5 of both
// sides: 98.70 % together, the worst frame 98.18 %; docs/decoding.md).
TEST_P(TrackChainFaces, LabelsAreRightAndCentresSubPixel) {
  const Side side = GetParam();
  for (std::uint32_t seed : {1u, 2u}) {
    const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, side, seed);
    const DecodeResult r = Decode(frame.image, side, TrackChain());
    ASSERT_TRUE(r.ok) << r.error;
    const Evaluation e = Evaluate(frame, r);
    EXPECT_EQ(e.all.wrong_p, 0) << e.all.Summary();
    EXPECT_EQ(e.all.wrong_v, 0) << e.all.Summary();
    EXPECT_GE(e.all.Recall(), 0.98) << e.all.Summary();
    EXPECT_LE(e.line_rms, 0.15) << "points " << e.line_points;
    EXPECT_GT(e.line_points, 4000);
    // One point per row of a line, in order.
    for (const DecodedLine& line : r.lines)
      for (size_t k = 1; k < line.points.size(); ++k)
        EXPECT_GT(line.points[k].y, line.points[k - 1].y) << "line " << line.p;
  }
}

INSTANTIATE_TEST_SUITE_P(BothSides, TrackChainFaces, ::testing::Values(Side::kLeft, Side::kRight),
                         [](const auto& test_info) {
                           return std::string(pattern::ToString(test_info.param));
                         });

TEST(TrackChain, TheResultDoesNotDependOnTheThreadCount) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kFace, Side::kLeft, 1);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const DecodeResult one = Decode(frame.image, Side::kLeft, TrackChain());
  cv::setNumThreads(std::max(threads, 2));
  const DecodeResult two = Decode(frame.image, Side::kLeft, TrackChain());
  cv::setNumThreads(threads);
  ASSERT_TRUE(one.ok && two.ok);
  ASSERT_NO_FATAL_FAILURE(ExpectSameJunctions(one, two));
  ASSERT_EQ(one.lines.size(), two.lines.size());
  for (size_t i = 0; i < one.lines.size(); ++i) EXPECT_EQ(one.lines[i].points, two.lines[i].points);
}

TEST(TrackChain, FrameWithoutReferenceLineIsReportedNotGuessed) {
  simulator::ThesisSceneOptions options;
  options.reference_cross = true;
  const simulator::Frame cross = simulator::Render(
      simulator::ThesisScene(Side::kLeft, SurfaceKind::kPlane, options), simulator::RenderParams{});
  const DecodeResult r = Decode(cross.image, Side::kLeft, TrackChain());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("reference line"), std::string::npos) << r.error;

  simulator::Frame face = RenderFrame(SurfaceKind::kFace, Side::kLeft, 5);
  face.image.colRange(300, 512).setTo(6);
  const DecodeResult cut = Decode(face.image, Side::kLeft, TrackChain());
  EXPECT_FALSE(cut.ok);
  EXPECT_NE(cut.error.find("line 0"), std::string::npos) << cut.error;
}

TEST(TrackChain, OutputsFollowTheContracts) {
  const simulator::Frame frame = RenderFrame(SurfaceKind::kPlane, Side::kRight, 7);
  DecodeParams params = TrackChain();
  params.q_offset = 4;
  const DecodeResult r = Decode(frame.image, Side::kRight, params);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.q_absolute);
  const nlohmann::json j = ToJson(r);
  EXPECT_EQ(j["side"], "right");
  EXPECT_EQ(j["junctions"].size(), r.junctions.size());
  for (size_t i = 1; i < r.junctions.size(); ++i) {
    const auto& a = r.junctions[i - 1];
    const auto& b = r.junctions[i];
    EXPECT_TRUE(a.p < b.p || (a.p == b.p && a.q < b.q)) << "junctions out of order";
  }
  const cv::Mat overlay = RenderOverlay(frame.image, r);
  EXPECT_EQ(overlay.size(), frame.image.size());
  EXPECT_EQ(r.skeleton.size(), frame.image.size());
  EXPECT_GT(r.times.total_ms, 0.0);
}

}  // namespace
}  // namespace bsls::decoder::test
