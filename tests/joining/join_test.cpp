// Joining the two sides of the simulated face (thesis 5.2.2): the right side
// displaced by a known rigid motion (the rig set up again) and recovered by
// the nose-and-mouth match and ICP; the shared-frame merge; bad input.
#include "bsls/joining/join.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "face_fixture.h"

namespace bsls::joining {
namespace {

// Acceptance: without noise the motion comes back within 0.1 deg, 0.1 mm.
constexpr double kExactRotationDeg = 0.1;
constexpr double kExactTranslationMm = 0.1;
// Sigma of the simulated reconstruction noise (along z, each side its own).
constexpr double kNoiseMm = 0.1;
// With that noise: bounds a few times the spread measured (docs/joining.md).
constexpr double kNoisyRotationDeg = 0.05;
constexpr double kNoisyTranslationMm = 0.2;
// The feature match alone (before ICP) must already be close: ICP refines it.
constexpr double kFeatureRotationDeg = 2.0;
constexpr double kFeatureTranslationMm = 3.0;
// Seam error: ~0 without noise; with noise, between these multiples of sigma
// (two independent noisy lines: sqrt(2) sigma at most, less across the curve).
constexpr double kExactSeamMm = 0.01;
constexpr double kSeamMinSigmas = 0.5;
constexpr double kSeamMaxSigmas = 2.0;

double AngleDeg(const Eigen::Matrix3d& r) {
  return Eigen::AngleAxisd(r).angle() * 180.0 / std::numbers::pi;
}

// The set-up error applied to the right side: a few degrees, a few mm.
struct Displacement {
  const char* name;
  double angle_deg;
  Eigen::Vector3d axis;
  Eigen::Vector3d translation_mm;

  Eigen::Isometry3d Transform() const {
    return Eigen::Translation3d(translation_mm) *
           Eigen::AngleAxisd(angle_deg * std::numbers::pi / 180.0, axis.normalized());
  }
};

const Displacement kDisplacements[] = {
    {"turned 3 deg, shifted 4 mm", 3.0, {0.3, 1.0, 0.2}, {2.5, -1.5, 3.0}},
    {"pitched 4 deg, shifted 3 mm", 4.0, {1.0, 0.1, 0.0}, {-1.0, 2.0, -2.0}},
    {"rolled 2 deg, shifted 5 mm", 2.0, {0.0, 0.2, 1.0}, {3.0, 3.0, 2.5}},
};

struct Recovery {
  double rotation_error_deg;
  double translation_error_mm;
};

// The error of `result` against the inverse of `displacement`: what is left
// when the recovered transform follows the displacement.
Recovery ErrorOf(const JoinResult& result, const Eigen::Isometry3d& displacement) {
  Eigen::Isometry3d recovered = Eigen::Isometry3d::Identity();
  recovered.linear() = result.rotation;
  recovered.translation() = result.translation;
  const Eigen::Isometry3d residual = recovered * displacement;
  return {AngleDeg(residual.linear()), residual.translation().norm()};
}

// The same for the feature match alone.
Recovery InitialErrorOf(const JoinResult& result, const Eigen::Isometry3d& displacement) {
  JoinResult initial;
  initial.rotation = result.initial_rotation;
  initial.translation = result.initial_translation;
  return ErrorOf(initial, displacement);
}

TEST(JoinByFeaturesTest, RecoversAKnownDisplacementWithoutNoise) {
  const geometry::SurfaceMesh left = test::SampleSide(pattern::Side::kLeft, 0.0, 1);
  const geometry::SurfaceMesh right = test::SampleSide(pattern::Side::kRight, 0.0, 2);
  for (const Displacement& displacement : kDisplacements) {
    SCOPED_TRACE(displacement.name);
    const Eigen::Isometry3d moved = displacement.Transform();
    const JoinResult result = JoinByFeatures(left, test::Moved(right, moved), {});
    const Recovery error = ErrorOf(result, moved);
    const Recovery initial = InitialErrorOf(result, moved);
    std::printf(
        "%s: features alone %.3f deg %.3f mm; after ICP (%d iterations) %.5f deg %.5f mm; "
        "seam RMS %.4f mm over %d samples; scale %.4f\n",
        displacement.name, initial.rotation_error_deg, initial.translation_error_mm,
        result.iterations, error.rotation_error_deg, error.translation_error_mm, result.seam.rms_mm,
        result.seam.samples, result.feature_scale);
    EXPECT_LT(initial.rotation_error_deg, kFeatureRotationDeg);
    EXPECT_LT(initial.translation_error_mm, kFeatureTranslationMm);
    EXPECT_LT(error.rotation_error_deg, kExactRotationDeg);
    EXPECT_LT(error.translation_error_mm, kExactTranslationMm);
    EXPECT_LT(result.seam.rms_mm, kExactSeamMm);
    EXPECT_GT(result.seam.samples, 100);
    std::string why;
    EXPECT_TRUE(result.mesh.IsValid(&why)) << why;
    EXPECT_GT(result.zipper_triangles, 100);
  }
}

TEST(JoinByFeaturesTest, RecoversAKnownDisplacementWithNoise) {
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    const geometry::SurfaceMesh left = test::SampleSide(pattern::Side::kLeft, kNoiseMm, seed);
    const geometry::SurfaceMesh right =
        test::SampleSide(pattern::Side::kRight, kNoiseMm, seed + 100);
    for (const Displacement& displacement : kDisplacements) {
      SCOPED_TRACE(displacement.name);
      const Eigen::Isometry3d moved = displacement.Transform();
      const JoinResult result = JoinByFeatures(left, test::Moved(right, moved), {});
      const Recovery error = ErrorOf(result, moved);
      const Recovery initial = InitialErrorOf(result, moved);
      std::printf(
          "noise %.2f mm, seed %u, %s: features alone %.3f deg %.3f mm; after ICP (%d "
          "iterations) %.4f deg %.4f mm; seam RMS %.4f mm\n",
          kNoiseMm, seed, displacement.name, initial.rotation_error_deg,
          initial.translation_error_mm, result.iterations, error.rotation_error_deg,
          error.translation_error_mm, result.seam.rms_mm);
      EXPECT_LT(initial.rotation_error_deg, kFeatureRotationDeg);
      EXPECT_LT(initial.translation_error_mm, kFeatureTranslationMm);
      EXPECT_LT(error.rotation_error_deg, kNoisyRotationDeg);
      EXPECT_LT(error.translation_error_mm, kNoisyTranslationMm);
      EXPECT_GT(result.seam.rms_mm, kSeamMinSigmas * kNoiseMm);
      EXPECT_LT(result.seam.rms_mm, kSeamMaxSigmas * kNoiseMm);
    }
  }
}

TEST(JoinByFeaturesTest, ShrugsOffOutliersOnTheCommonLine) {
  // Every 15th vertex of the right reference line 4 mm off (a bad junction,
  // a bridged gap): trimming and the Huber weights keep them out.
  const geometry::SurfaceMesh left = test::SampleSide(pattern::Side::kLeft, kNoiseMm, 1);
  geometry::SurfaceMesh right = test::SampleSide(pattern::Side::kRight, kNoiseMm, 101);
  constexpr int kEvery = 15;
  constexpr double kOutlierMm = 4.0;
  int outliers = 0;
  for (std::size_t v = 0; v < right.VertexCount(); ++v) {
    if (right.line[v] == 0 && v % kEvery == 0) {
      right.positions[v].z() += kOutlierMm;
      ++outliers;
    }
  }
  ASSERT_GT(outliers, 10);
  const Eigen::Isometry3d moved = kDisplacements[0].Transform();
  JoinParams plain;
  plain.icp.trim_fraction = 0.0;
  plain.icp.huber_mm = 1e3;
  const Recovery plain_error =
      ErrorOf(JoinByFeatures(left, test::Moved(right, moved), plain), moved);
  // Plain least squares is thrown off by them: the case tests the robustness.
  EXPECT_GT(plain_error.translation_error_mm, kNoisyTranslationMm);
  const JoinResult result = JoinByFeatures(left, test::Moved(right, moved), {});
  const Recovery error = ErrorOf(result, moved);
  std::printf("%d outliers of %.0f mm: robust %.4f deg %.4f mm, plain %.4f deg %.4f mm\n", outliers,
              kOutlierMm, error.rotation_error_deg, error.translation_error_mm,
              plain_error.rotation_error_deg, plain_error.translation_error_mm);
  EXPECT_LT(error.rotation_error_deg, kNoisyRotationDeg);
  EXPECT_LT(error.translation_error_mm, kNoisyTranslationMm);
}

TEST(JoinByFeaturesTest, ReportsAnIcpThatDoesNotConverge) {
  const geometry::SurfaceMesh left = test::SampleSide(pattern::Side::kLeft, 0.0, 1);
  const geometry::SurfaceMesh right =
      test::Moved(test::SampleSide(pattern::Side::kRight, 0.0, 2), kDisplacements[0].Transform());
  JoinParams params;
  params.icp.max_iterations = 1;
  try {
    JoinByFeatures(left, right, params);
    FAIL() << "one ICP step converged from a feature match";
  } catch (const JoinError& error) {
    EXPECT_EQ(error.reason(), JoinError::Reason::kNotConverged);
    EXPECT_NE(std::string(error.what()).find("right mesh"), std::string::npos) << error.what();
  }
}

TEST(JoinByFeaturesTest, AFlatSurfaceHasNoFeatures) {
  const simulator::PlaneSurface plane = simulator::PlaneSurface::Horizontal(20.0);
  testing::StripeSampling sampling;
  const geometry::SurfaceMesh left = testing::SampleStripes(plane, sampling);
  sampling.side = pattern::Side::kRight;
  const geometry::SurfaceMesh right = testing::SampleStripes(plane, sampling);
  try {
    JoinByFeatures(left, right, {});
    FAIL() << "a plane has a nose";
  } catch (const JoinError& error) {
    EXPECT_EQ(error.reason(), JoinError::Reason::kFeaturesNotFound);
    EXPECT_NE(std::string(error.what()).find("left mesh"), std::string::npos) << error.what();
  }
}

TEST(JoinSharedFrameTest, SeamErrorIsTheNoise) {
  const geometry::SurfaceMesh exact_left = test::SampleSide(pattern::Side::kLeft, 0.0, 1);
  const geometry::SurfaceMesh exact_right = test::SampleSide(pattern::Side::kRight, 0.0, 2);
  const JoinResult exact = JoinSharedFrame(exact_left, exact_right, {});
  EXPECT_LT(exact.seam.rms_mm, kExactSeamMm);

  const geometry::SurfaceMesh left = test::SampleSide(pattern::Side::kLeft, kNoiseMm, 1);
  const geometry::SurfaceMesh right = test::SampleSide(pattern::Side::kRight, kNoiseMm, 2);
  const JoinResult result = JoinSharedFrame(left, right, {});
  std::printf(
      "shared frame: seam RMS %.4f mm (noise %.2f mm), max %.3f mm, %d samples; "
      "%d zipper triangles, %d skipped\n",
      result.seam.rms_mm, kNoiseMm, result.seam.max_mm, result.seam.samples,
      result.zipper_triangles, result.skipped_zipper_triangles);
  EXPECT_GT(result.seam.rms_mm, kSeamMinSigmas * kNoiseMm);
  EXPECT_LT(result.seam.rms_mm, kSeamMaxSigmas * kNoiseMm);
  std::string why;
  ASSERT_TRUE(result.mesh.IsValid(&why)) << why;
  std::size_t right_reference = 0;
  for (std::int32_t p : right.line) right_reference += p == 0;
  EXPECT_EQ(result.mesh.VertexCount(), left.VertexCount() + right.VertexCount() - right_reference);
  EXPECT_EQ(result.right_vertex_offset, left.VertexCount());
  EXPECT_GT(result.zipper_triangles, 100);
  EXPECT_TRUE(result.rotation.isIdentity());
  EXPECT_EQ(result.iterations, 0);
  // Every vertex of the joined mesh keeps its side: left at x <= 0, right at x > 0.
  for (std::size_t v = 0; v < result.mesh.VertexCount(); ++v) {
    if (v < result.right_vertex_offset)
      EXPECT_LE(result.mesh.positions[v].x(), 0.0) << v;
    else
      EXPECT_GT(result.mesh.positions[v].x(), 0.0) << v;
  }
}

// The reason and the named side of a join that must fail.
void ExpectFailure(const geometry::SurfaceMesh& left, const geometry::SurfaceMesh& right,
                   const JoinParams& params, JoinError::Reason reason, const std::string& named) {
  for (auto join : {&JoinSharedFrame, &JoinByFeatures}) {
    try {
      join(left, right, params, Cancellation());
      ADD_FAILURE() << "joined; expected an error naming " << named;
    } catch (const JoinError& error) {
      EXPECT_EQ(error.reason(), reason) << error.what();
      EXPECT_NE(std::string(error.what()).find(named), std::string::npos) << error.what();
    }
  }
}

TEST(JoinBadInputTest, NamesTheSideAndTheReason) {
  const geometry::SurfaceMesh left = test::SampleSide(pattern::Side::kLeft, 0.0, 1);
  const geometry::SurfaceMesh right = test::SampleSide(pattern::Side::kRight, 0.0, 2);
  // Empty.
  ExpectFailure({}, right, {}, JoinError::Reason::kInvalidInput, "left mesh: empty");
  // No line 0: the right side without its reference line.
  geometry::SurfaceMesh no_reference;
  for (std::size_t v = 0; v < right.VertexCount(); ++v) {
    if (right.line[v] == 0) continue;
    no_reference.positions.push_back(right.positions[v]);
    no_reference.line.push_back(right.line[v]);
  }
  ExpectFailure(left, no_reference, {}, JoinError::Reason::kNoReferenceLine,
                "right mesh: 0 vertices");
  // No labels at all.
  geometry::SurfaceMesh unlabelled = right;
  unlabelled.line.clear();
  ExpectFailure(left, unlabelled, {}, JoinError::Reason::kNoReferenceLine,
                "right mesh: no line labels");
  // Inconsistent attributes.
  geometry::SurfaceMesh broken = left;
  broken.normals.pop_back();
  ExpectFailure(broken, right, {}, JoinError::Reason::kInvalidInput, "left mesh");
  // Parameters.
  JoinParams params;
  params.icp.huber_mm = -1.0;
  ExpectFailure(left, right, params, JoinError::Reason::kInvalidInput, "parameters: icp: huber_mm");
}

TEST(JoinParamsTest, DefaultsAreValid) {
  std::string why;
  EXPECT_TRUE(JoinParams{}.IsValid(&why)) << why;
  JoinParams params;
  params.stitch.max_edge_mm = 0.0;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("stitch: max_edge_mm"), std::string::npos) << why;
}

}  // namespace
}  // namespace bsls::joining
