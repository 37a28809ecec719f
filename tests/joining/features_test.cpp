// Thesis 5.2.2 features of the common line: the nose and the mouth found on
// the reference line of either side of the simulated face.
#include "bsls/joining/features.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bsls/joining/join_error.h"
#include "face_fixture.h"

namespace bsls::joining {
namespace {

constexpr double kMaxGapMm = 3.0;
constexpr double kNoiseMm = 0.1;
// Both sides sample the same curve (the same projector rays on line 0), so
// their features agree to the smoothing's effect on noise.
constexpr double kSameFeatureMm = 1.0;

StripeCurve ReferenceLineOf(pattern::Side side, double noise_mm, std::uint32_t seed) {
  return StripeCurve::FromMesh(test::SampleSide(side, noise_mm, seed), 0, kMaxGapMm);
}

TEST(LineFeaturesTest, FindsNoseAndMouthOnTheFaceMidline) {
  const StripeCurve line = ReferenceLineOf(pattern::Side::kLeft, 0.0, 1);
  ASSERT_GT(line.size(), 100u);
  const LineFeatures features = FindLineFeatures(line, {}, "left");
  for (const TurningPoint& tp : features.turning_points)
    std::printf("turning point %s y %.1f z %.1f\n", tp.maximum ? "max" : "min", tp.position.y(),
                tp.position.z());
  const auto points = features.ControlPoints();
  std::printf("nose y %.1f z %.1f; lips y %.1f / %.1f; mouth y %.1f\n", points[0].y(),
              points[0].z(), points[1].y(), points[3].y(), points[2].y());
  // The nose is the highest point of the midline (the face is placed so).
  double top_z = -1e9;
  for (const Eigen::Vector3d& p : line.points()) top_z = std::max(top_z, p.z());
  EXPECT_NEAR(points[0].z(), top_z, kSameFeatureMm);
  EXPECT_TRUE(features.turning_points[features.nose].maximum);
  // Lips are peaks, the mouth a valley between them, all below the nose.
  EXPECT_TRUE(features.turning_points[features.upper_lip].maximum);
  EXPECT_FALSE(features.turning_points[features.mouth].maximum);
  EXPECT_TRUE(features.turning_points[features.lower_lip].maximum);
  EXPECT_LT(points[1].y(), points[0].y());
  EXPECT_LT(points[2].y(), points[1].y());
  EXPECT_LT(points[3].y(), points[2].y());
  EXPECT_LT(points[2].z(), points[1].z());
  EXPECT_LT(points[2].z(), points[3].z());
}

TEST(LineFeaturesTest, BothSidesAgreeUnderNoise) {
  const LineFeatures left =
      FindLineFeatures(ReferenceLineOf(pattern::Side::kLeft, kNoiseMm, 1), {}, "left");
  const LineFeatures right =
      FindLineFeatures(ReferenceLineOf(pattern::Side::kRight, kNoiseMm, 2), {}, "right");
  const auto a = left.ControlPoints();
  const auto b = right.ControlPoints();
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_LT((a[k] - b[k]).norm(), kSameFeatureMm) << k;
}

TEST(LineFeaturesTest, AStraightLineHasNoNose) {
  geometry::SurfaceMesh mesh;
  for (int i = 0; i < 200; ++i) {
    mesh.positions.emplace_back(0.0, 50.0 - 0.5 * i, 20.0);
    mesh.line.push_back(0);
  }
  const StripeCurve line = StripeCurve::FromMesh(mesh, 0, kMaxGapMm);
  try {
    FindLineFeatures(line, {}, "left");
    FAIL() << "a flat line has a nose";
  } catch (const JoinError& error) {
    EXPECT_EQ(error.reason(), JoinError::Reason::kFeaturesNotFound);
    EXPECT_NE(std::string(error.what()).find("left mesh"), std::string::npos) << error.what();
  }
}

TEST(LineFeaturesTest, ANoseWithoutMouthIsReported) {
  // A bump (the nose) and a valley below it, but no peak after the valley.
  geometry::SurfaceMesh mesh;
  for (int i = 0; i < 200; ++i) {
    const double y = 50.0 - 0.5 * i;
    const double dip = y + 30.0;
    mesh.positions.emplace_back(0.0, y,
                                20.0 * std::exp(-y * y / 50.0) - 5.0 * std::exp(-dip * dip / 20.0) -
                                    0.1 * std::min(dip, 0.0));
    mesh.line.push_back(0);
  }
  try {
    FindLineFeatures(StripeCurve::FromMesh(mesh, 0, kMaxGapMm), {}, "right");
    FAIL() << "a single bump has a mouth";
  } catch (const JoinError& error) {
    EXPECT_EQ(error.reason(), JoinError::Reason::kFeaturesNotFound);
    EXPECT_NE(std::string(error.what()).find("mouth"), std::string::npos) << error.what();
  }
}

TEST(FeatureParamsTest, RejectsOutOfRange) {
  FeatureParams params;
  std::string why;
  EXPECT_TRUE(params.IsValid(&why));
  params.min_turn_mm = 0.0;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("min_turn_mm"), std::string::npos);
  params = {};
  params.max_nose_to_mouth_mm = params.min_nose_to_mouth_mm;
  EXPECT_FALSE(params.IsValid(&why));
}

}  // namespace
}  // namespace bsls::joining
