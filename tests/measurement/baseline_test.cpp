// Registration of a scan onto its baseline and lesions measured against it,
// on the simulated face sampled as the rig samples it (no reconstruction:
// the whole chain is lesion_chain_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "bsls/measurement/baseline_registration.h"
#include "bsls/measurement/lesion_measure.h"
#include "bsls/simulator/lesion.h"
#include "bsls/simulator/scene.h"
#include "bsls/testing/build_paths.h"
#include "bsls/testing/surface_sampling.h"

namespace bsls::measurement {
namespace {

const std::filesystem::path kDataDir = bsls::testing::TestDataDir();
constexpr double kNoiseMm = 0.05;

std::shared_ptr<const simulator::Surface> Face() {
  simulator::FaceModelParams face;
  face.obj_path = kDataDir / "canonical_face_model.obj";
  return std::make_shared<simulator::MeshSurface>(simulator::LoadFaceMesh(face), "face");
}

geometry::SurfaceMesh Sample(const simulator::Surface& surface, std::uint32_t seed) {
  testing::StripeSampling stripes;
  stripes.noise_mm = kNoiseMm;
  stripes.seed = seed;
  return testing::SampleStripes(surface, stripes);
}

Polygon2d Square(const Eigen::Vector2d& centre, double half) {
  return {centre + Eigen::Vector2d(-half, -half), centre + Eigen::Vector2d(half, -half),
          centre + Eigen::Vector2d(half, half), centre + Eigen::Vector2d(-half, half)};
}

Eigen::Isometry3d Motion() {
  return Eigen::Translation3d(1.5, 2.0, -1.0) *
         Eigen::AngleAxisd(1.5 * std::numbers::pi / 180.0,
                           Eigen::Vector3d(1.0, -0.4, 0.3).normalized());
}

TEST(RegisterToBaselineTest, RecoversTheMotionBetweenTwoScans) {
  const auto face = Face();
  const geometry::SurfaceMesh scan = Sample(*face, 1);
  geometry::SurfaceMesh baseline = Sample(*face, 2);
  for (Eigen::Vector3d& p : baseline.positions) p = Motion() * p;
  const SurfaceQuery surface(scan), reference(baseline);
  const BaselineRegistration r = RegisterToBaseline(surface, reference, {}, {});
  const Eigen::Isometry3d error = Motion().inverse() * r.transform;
  EXPECT_LT(error.translation().norm(), 0.05);
  // The baseline is resampled between its stripes (5.7 mm apart): ~0.04 mm of bias at 100 mm.
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle() * 180.0 / std::numbers::pi, 0.05);
  EXPECT_GT(r.pairs, 1000);
  EXPECT_LT(r.rms_mm, 3.0 * kNoiseMm);  // both scans' noise
  EXPECT_TRUE(r.rigid);
}

TEST(RegisterToBaselineTest, APlaneDoesNotFixAMotion) {
  const simulator::PlaneSurface plane = simulator::PlaneSurface::Horizontal(0.0);
  const geometry::SurfaceMesh scan = testing::SampleGrid(plane, {});
  const SurfaceQuery surface(scan), reference(scan);
  try {
    RegisterToBaseline(surface, reference, {}, {});
    FAIL() << "a plane was registered";
  } catch (const MeasurementError& e) {
    EXPECT_NE(std::string(e.what()).find("does not fix a rigid motion"), std::string::npos);
  }
  BaselineParams same_frame;
  same_frame.register_rigidly = false;
  const BaselineRegistration kept = RegisterToBaseline(surface, reference, {}, same_frame);
  EXPECT_FALSE(kept.rigid);
  EXPECT_TRUE(kept.transform.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(RegisterToBaselineTest, RefusesScansThatDoNotOverlapAndBadParams) {
  const auto face = Face();
  const geometry::SurfaceMesh scan = Sample(*face, 1);
  geometry::SurfaceMesh far = scan;
  for (Eigen::Vector3d& p : far.positions) p.x() += 500.0;
  const SurfaceQuery surface(scan), reference(far);
  EXPECT_THROW(RegisterToBaseline(surface, reference, {}, {}), MeasurementError);
  BaselineParams bad;
  bad.min_coverage = 0.0;
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("min_coverage"), std::string::npos);
  EXPECT_THROW(RegisterToBaseline(surface, SurfaceQuery(scan), {}, bad), MeasurementError);
}

// A lump that grew on the cheek, measured against the scan before it, taken
// in another pose: within the acceptance although the cheek under
// it is not a smooth surface a ring could know.
TEST(MeasureLesionAgainstBaselineTest, MeasuresAGrownLumpInAnotherPose) {
  const simulator::LesionParams lump{
      .centre_xy_mm = {-40.0, -5.0}, .height_mm = 8.0, .radius_mm = 18.0, .top_radius_mm = 5.0};
  const auto face = Face();
  const simulator::LesionSurface grown(face, {lump});
  const geometry::SurfaceMesh scan = Sample(grown, 3);
  geometry::SurfaceMesh before = Sample(*face, 4);
  for (Eigen::Vector3d& p : before.positions) p = Motion() * p;
  const SurfaceQuery surface(scan);
  const Polygon2d region = Square(lump.centre_xy_mm, lump.radius_mm + 2.0);
  const LesionMeasurement m = MeasureLesionAgainstBaseline(surface, before, region);
  const simulator::LesionTruth truth = grown.Truth(0, LesionMeasureParams{}.level_fraction);
  EXPECT_FALSE(m.cavity);
  EXPECT_NEAR(m.peak_mm.value, truth.peak_mm, 0.5);
  EXPECT_NEAR(m.area_mm2.value, truth.area_on_base_mm2, 0.03 * truth.area_on_base_mm2);
  EXPECT_NEAR(m.volume_mm3.value, truth.volume_mm3, 0.05 * truth.volume_mm3);
  EXPECT_EQ(m.reference.kind, ReferenceKind::kBaseline);
  ASSERT_TRUE(m.baseline.has_value());
  EXPECT_GT(m.surface_coverage, 0.99);
  // A fitted reference kind is refused where a baseline is meant, and the
  // other way round.
  LesionMeasureParams baseline_kind;
  baseline_kind.reference = ReferenceKind::kBaseline;
  EXPECT_THROW(MeasureLesion(surface, region, baseline_kind), MeasurementError);
  EXPECT_THROW(MeasureLesionAgainstBaseline(surface, geometry::SurfaceMesh{}, region),
               MeasurementError);
}

}  // namespace
}  // namespace bsls::measurement
