#include "bsls/simulator/random_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "bsls/extraction/stripe_pitch.h"
#include "bsls/simulator/ground_truth.h"
#include "bsls/simulator/renderer.h"
#include "test_options.h"

namespace bsls::simulator {
namespace {

using pattern::Side;

// Draws checked for their ranges: cheap (no rendering).
constexpr int kDrawnScenes = 400;
// Scenes whose ground truth is traced (one ray per pixel).
constexpr int kTracedScenes = 10;
// The decoder's pitch measurement against the target at the aim point: the
// pitch varies over the frame (slopes, heights, perspective).
constexpr double kPitchTolerance = 0.3;  // relative
// Visible junctions on line 0 that make it visible (bench/decoder/heldout_report).
constexpr int kLineZeroJunctions = 3;
// Neighbouring junctions farther apart than this (mm; the projected pitch is
// 4-8 mm) lie across an occluding edge.
constexpr double kSameSurfaceMm = 12.0;

RandomSceneData TestData() {
  return {kDataDir / "canonical_face_model.obj", kDataDir / "stanford_bunny.json"};
}

// Ranges whose images stay small (512-640 px), for tests that trace or render.
RandomSceneRanges SmallImages() {
  RandomSceneRanges ranges;
  ranges.image_size_px = {512.0, 640.0};
  return ranges;
}

TEST(RandomSceneSeeds, TuningAndHeldOutSetsAreDisjoint) {
  EXPECT_EQ(SeedOf(SeedSet::kTuning, 0), kTuningFirstSeed);
  EXPECT_EQ(SeedOf(SeedSet::kHeldOut, 0), kHeldOutFirstSeed);
  const std::uint32_t last_tuning = SeedOf(SeedSet::kTuning, kHeldOutFirstSeed - 2);
  EXPECT_EQ(last_tuning, kHeldOutFirstSeed - 1);
  EXPECT_EQ(SetOfSeed(last_tuning), SeedSet::kTuning);
  EXPECT_EQ(SetOfSeed(kHeldOutFirstSeed), SeedSet::kHeldOut);
  EXPECT_THROW(SeedOf(SeedSet::kTuning, kHeldOutFirstSeed - 1), std::invalid_argument);
  EXPECT_THROW(SetOfSeed(0), std::invalid_argument);
  EXPECT_THROW(DrawRandomScene(0), std::invalid_argument);
  for (int i = 0; i < 1000; ++i) {
    EXPECT_EQ(SetOfSeed(SeedOf(SeedSet::kTuning, i)), SeedSet::kTuning);
    EXPECT_EQ(SetOfSeed(SeedOf(SeedSet::kHeldOut, i)), SeedSet::kHeldOut);
    EXPECT_EQ(DrawRandomScene(SeedOf(SeedSet::kHeldOut, i)).set, SeedSet::kHeldOut);
  }
}

TEST(RandomScene, IsReproducibleFromItsSeed) {
  for (const std::uint32_t seed : {1u, 17u, kHeldOutFirstSeed, kHeldOutFirstSeed + 123}) {
    EXPECT_EQ(ToJson(DrawRandomScene(seed)), ToJson(DrawRandomScene(seed))) << seed;
    EXPECT_NE(ToJson(DrawRandomScene(seed)), ToJson(DrawRandomScene(seed + 1))) << seed;
  }
  // Rendered twice, a frame is the same to the last grey level.
  RandomScene a = MakeRandomScene(kHeldOutFirstSeed + 4, TestData(), SmallImages());
  RandomScene b = MakeRandomScene(kHeldOutFirstSeed + 4, TestData(), SmallImages());
  a.render.supersampling = b.render.supersampling = 1;  // the draws are what is tested
  const cv::Mat image_a = Renderer(a.scene, a.render).RenderImage(a.render.seed);
  const cv::Mat image_b = Renderer(b.scene, b.render).RenderImage(b.render.seed);
  ASSERT_EQ(image_a.size(), image_b.size());
  EXPECT_EQ(cv::countNonZero(image_a != image_b), 0);
  EXPECT_FALSE(a.draw.Describe().empty());
}

TEST(RandomScene, DrawsFallInTheirRanges) {
  const RandomSceneRanges r;
  std::map<RandomObject, int> objects;
  std::set<Side> sides;
  int beyond = 0, framed = 0;
  double min_pitch = 1e9, max_pitch = 0.0, min_size = 1e9, max_size = 0.0;
  for (int i = 0; i < kDrawnScenes; ++i) {
    const std::uint32_t seed = SeedOf(i % 2 ? SeedSet::kTuning : SeedSet::kHeldOut, i);
    const RandomSceneDraw d = DrawRandomScene(seed);
    SCOPED_TRACE(d.Describe());
    ++objects[d.object];
    sides.insert(d.side);
    beyond += d.beyond_tolerance;
    framed += d.line_zero_framed;
    for (const int size : {d.width, d.height}) {
      EXPECT_TRUE(r.image_size_px.Contains(size));
      min_size = std::min<double>(min_size, size);
      max_size = std::max<double>(max_size, size);
    }
    EXPECT_TRUE(r.stripe_pitch_px.Contains(d.stripe_pitch_px));
    min_pitch = std::min(min_pitch, d.stripe_pitch_px);
    max_pitch = std::max(max_pitch, d.stripe_pitch_px);
    EXPECT_TRUE(r.face_height_mm.Contains(d.subject_height_mm));
    EXPECT_LE(std::abs(d.face_yaw_deg), r.face_yaw_deg);
    EXPECT_LE(std::abs(d.face_pitch_deg), r.face_pitch_deg);
    EXPECT_TRUE(r.camera_k1.Contains(d.camera_k1));
    EXPECT_TRUE(r.camera_k2.Contains(d.camera_k2));
    // The subject keeps within the frame (the pitch range may push the fill
    // out of subject_fill only where the two cannot both hold).
    EXPECT_GT(d.subject_fill, 0.25);
    EXPECT_LT(d.subject_fill, 1.0);
    // Set-up errors: the class decides their size.
    const double lateral = std::abs(d.camera_centre_mm.x() - d.projector_centre_mm.x());
    const double angles[] = {d.projector_tilt_x_deg, d.projector_tilt_y_deg, d.projector_roll_deg,
                             d.camera_aim_x_deg,     d.camera_aim_y_deg,     d.camera_roll_deg};
    if (d.beyond_tolerance) {
      EXPECT_TRUE(r.projector_height_mm.Contains(d.projector_centre_mm.z()));
      EXPECT_TRUE(r.projector_focal_d.Contains(d.projector_focal_d));
      EXPECT_TRUE(r.camera_baseline_mm.Contains(lateral));
      EXPECT_TRUE(r.camera_height_mm.Contains(d.camera_centre_mm.z()));
      for (const double a : angles) EXPECT_LE(std::abs(a), 3.0);
    } else {
      EXPECT_NEAR(d.projector_centre_mm.z(), 730.0, r.within_position_mm);
      EXPECT_NEAR(d.projector_focal_d, 128.0, r.within_focal_d);
      EXPECT_NEAR(lateral, 240.0, r.within_position_mm);
      EXPECT_NEAR(d.camera_centre_mm.z(), 340.0, r.within_position_mm);
      for (const double a : angles) EXPECT_LE(std::abs(a), r.within_angle_deg);
    }
    // The camera of the left side stands at world x < 0, the right at x > 0.
    EXPECT_EQ(d.camera_centre_mm.x() < 0.0, d.side == Side::kLeft);
    // Line 0 meets the base plane at x = 0 on y = 0.
    const auto st = d.Projector().Project(Eigen::Vector3d::Zero());
    ASSERT_TRUE(st.has_value());
    EXPECT_NEAR(st->x(), 0.0, 1e-6);
  }
  EXPECT_EQ(objects.size(), 6u);
  for (const auto& [object, count] : objects) EXPECT_GE(count, 20) << ToString(object);
  EXPECT_GE(objects[RandomObject::kFace], kDrawnScenes / 3);
  EXPECT_EQ(sides.size(), 2u);
  // Nearly every draw frames line 0 in the central 80 % of the width.
  EXPECT_GE(framed, kDrawnScenes * 95 / 100);
  EXPECT_GT(beyond, kDrawnScenes / 2);
  EXPECT_LT(beyond, kDrawnScenes * 9 / 10);
  // The set spans the ranges.
  EXPECT_LT(min_size, 560.0);
  EXPECT_GT(max_size, 1900.0);
  EXPECT_LT(min_pitch, 9.0);
  EXPECT_GT(max_pitch, 55.0);
}

TEST(RandomScene, RejectsInvalidRangesByName) {
  RandomSceneRanges ranges;
  ranges.stripe_pitch_px = {64.0, 8.0};
  std::string error;
  EXPECT_FALSE(ranges.IsValid(&error));
  EXPECT_NE(error.find("stripe_pitch_px"), std::string::npos);
  EXPECT_THROW(DrawRandomScene(1, ranges), std::invalid_argument);
  ranges = RandomSceneRanges{};
  ranges.face_yaw_deg = -1.0;
  EXPECT_FALSE(ranges.IsValid(&error));
  EXPECT_NE(error.find("face_yaw_deg"), std::string::npos);
}

// Contracts section 2 on the traced truth: line 0 visible (on the face's
// midline for faces), p growing towards smaller image x on the left side and
// larger on the right, the lit side at world x < 0 (left) or x > 0 (right).
TEST(RandomScene, LineZeroIsVisibleAndTheSidesFollowTheContracts) {
  for (int i = 0; i < kTracedScenes; ++i) {
    const RandomScene random =
        MakeRandomScene(SeedOf(SeedSet::kHeldOut, i), TestData(), SmallImages());
    SCOPED_TRACE(random.draw.Describe());
    const GroundTruth truth = ComputeGroundTruth(random.scene);
    const bool left = random.draw.side == Side::kLeft;
    // (p, v) -> the visible junction there.
    std::map<std::pair<int, int>, const TruthJunction*> visible;
    int line_zero = 0, line_zero_raised = 0;
    for (const TruthJunction& j : truth.junctions) {
      if (!j.visible) continue;
      visible[{j.p, j.v}] = &j;
      if (j.p == 0) {
        ++line_zero;
        line_zero_raised += j.world.z() > random.draw.face_lift_mm + 10.0;
      }
      // Lines 3 and up lie on the lit side even with the projector's roll.
      if (j.p >= 3 && j.world.z() < 1.0) {
        EXPECT_EQ(j.world.x() < 0.0, left) << j.p << "," << j.v;
      }
    }
    EXPECT_GE(line_zero, kLineZeroJunctions);
    if (random.draw.object == RandomObject::kFace) {
      EXPECT_GE(line_zero_raised, kLineZeroJunctions);
    }
    // Junctions p and p + 1 on one row of one surface (their world points
    // about a pitch apart, not across an occluding edge): the segment between
    // them runs towards smaller image x on the left side.
    int pairs = 0;
    for (const auto& [pv, j] : visible) {
      const auto next = visible.find({pv.first + 1, pv.second});
      if (next == visible.end()) continue;
      if ((next->second->world - j->world).norm() > kSameSurfaceMm) continue;
      ++pairs;
      EXPECT_EQ(next->second->image.x() < j->image.x(), left)
          << "p " << pv.first << " v " << pv.second;
    }
    EXPECT_GT(pairs, 20);
  }
}

// The decoder's stripe-pitch measurement on the plane frames of the smallest
// and the largest drawn pitch: the rendered frames span the intended range.
// (Planes: one pitch over the whole frame.)
TEST(RandomScene, RenderedStripePitchSpansTheRange) {
  std::uint32_t smallest = 0, largest = 0;
  double small_pitch = 1e9, large_pitch = 0.0;
  for (int i = 0; i < kDrawnScenes; ++i) {
    const RandomSceneDraw d = DrawRandomScene(SeedOf(SeedSet::kHeldOut, i));
    if (d.object != RandomObject::kPlane) continue;
    if (d.stripe_pitch_px < small_pitch) {
      small_pitch = d.stripe_pitch_px;
      smallest = d.seed;
    }
    if (d.stripe_pitch_px > large_pitch) {
      large_pitch = d.stripe_pitch_px;
      largest = d.seed;
    }
  }
  ASSERT_LT(small_pitch, 10.0);
  ASSERT_GT(large_pitch, 45.0);
  for (const std::uint32_t seed : {smallest, largest}) {
    RandomScene random = MakeRandomScene(seed, TestData());
    SCOPED_TRACE(random.draw.Describe());
    random.render.supersampling = 1;  // the pitch does not need more
    const cv::Mat image = Renderer(random.scene, random.render).RenderImage(random.render.seed);
    const std::optional<double> pitch = extraction::MeasureStripePitch(image);
    ASSERT_TRUE(pitch.has_value());
    EXPECT_NEAR(*pitch / random.draw.stripe_pitch_px, 1.0, kPitchTolerance);
  }
}

}  // namespace
}  // namespace bsls::simulator
