// The lumps and cavities of thesis Tables 7.3-7.4 on the simulated face,
// sampled as the rig samples it (stripes 5.7 mm apart, 0.5 mm along them,
// 0.15 mm noise), measured against their exact ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numbers>
#include <string>

#include "bsls/measurement/lesion_measure.h"
#include "bsls/measurement/report.h"
#include "bsls/simulator/lesion.h"
#include "bsls/simulator/scene.h"
#include "bsls/testing/build_paths.h"
#include "bsls/testing/surface_sampling.h"

namespace bsls::measurement {
namespace {

const std::filesystem::path kDataDir = bsls::testing::TestDataDir();
// Acceptance of the issue: height/depth within 0.5 mm, area within 3 %.
constexpr double kPeakTolerance = 0.5;           // mm
constexpr double kAreaRelativeTolerance = 0.03;  // of the true area
constexpr double kVolumeRelativeTolerance = 0.05;
constexpr double kNoiseMm = 0.15;  // sigma of the simulated reconstruction

std::shared_ptr<const simulator::Surface> Face() {
  simulator::FaceModelParams face;
  face.obj_path = kDataDir / "canonical_face_model.obj";
  return std::make_shared<simulator::MeshSurface>(simulator::LoadFaceMesh(face), "face");
}

struct Case {
  const char* name;
  simulator::LesionParams lesion;
  pattern::Side side;
};

// Thesis 7.2 on the bundled face: a 15 mm lump on the cheek, a 15 mm cavity
// on the forehead and a 10 mm one low on the cheek, placed and sized where the
// face is smooth enough for a ring reference (its coarse model has bumps of
// ~0.5 mm at the scale of its 8 mm triangles, which no reference can know).
const Case kCases[] = {
    {"cheek lump",
     {.centre_xy_mm = {-40.0, -5.0}, .height_mm = 15.0, .radius_mm = 13.0, .top_radius_mm = 4.0},
     pattern::Side::kLeft},
    {"forehead cavity",
     {.centre_xy_mm = {-30.0, 68.0}, .height_mm = -15.0, .radius_mm = 13.0, .top_radius_mm = 4.0},
     pattern::Side::kLeft},
    {"cheek cavity",
     {.centre_xy_mm = {48.0, -52.0}, .height_mm = -10.0, .radius_mm = 11.0, .top_radius_mm = 3.0},
     pattern::Side::kRight},
};

// Thesis-sized lesions (Tables 7.3-7.4: 15 mm / ~1474 mm^2 lump, 15 mm /
// ~1240 mm^2 and 10 mm / ~412 mm^2 cavities) on a smooth cheek-like base (a
// ball of 160 mm radius): the method's own accuracy at the rig's sampling.
const Case kThesisCases[] = {
    {"thesis lump",
     {.centre_xy_mm = {-45.0, -10.0}, .height_mm = 15.0, .radius_mm = 30.0, .top_radius_mm = 12.0},
     pattern::Side::kLeft},
    {"thesis forehead cavity",
     {.centre_xy_mm = {-40.0, 30.0}, .height_mm = -15.0, .radius_mm = 28.0, .top_radius_mm = 11.0},
     pattern::Side::kLeft},
    {"thesis cheek cavity",
     {.centre_xy_mm = {45.0, -20.0}, .height_mm = -10.0, .radius_mm = 16.0, .top_radius_mm = 7.0},
     pattern::Side::kRight},
};
// On the face, the reference's error from the model's own bumps adds to the
// method's: looser bounds (docs/measurement.md).
constexpr double kFacePeakTolerance = 1.0;           // mm
constexpr double kFaceAreaRelativeTolerance = 0.13;  // small lesions: 2-3 stripes across
constexpr double kFaceVolumeRelativeTolerance = 0.12;

struct Errors {
  double peak_mm, area_relative, volume_relative;
};

// Samples `c` on `base` along the stripes, measures it and prints the figures.
Errors MeasureCase(const std::shared_ptr<const simulator::Surface>& base, const Case& c) {
  const auto decorated = std::make_shared<simulator::LesionSurface>(base, std::vector{c.lesion});
  testing::StripeSampling stripes;
  stripes.side = c.side;
  stripes.noise_mm = kNoiseMm;
  const geometry::SurfaceMesh mesh = testing::SampleStripes(*decorated, stripes);
  const SurfaceQuery surface(mesh);
  const LesionMeasureParams params;
  const simulator::LesionTruth truth = decorated->Truth(0, params.level_fraction);
  const Polygon2d region = testing::Circle(c.lesion.centre_xy_mm, c.lesion.radius_mm + 2.0);
  const LesionMeasurement m = MeasureLesion(surface, region, params);
  std::printf(
      "%s: peak %.2f +- %.2f (true %.2f) mm, area %.1f +- %.1f (true %.1f) mm^2, "
      "volume %.0f +- %.0f (true %.0f) mm^3, ring RMS %.3f mm\n",
      c.name, m.peak_mm.value, m.peak_mm.uncertainty, std::abs(truth.peak_mm), m.area_mm2.value,
      m.area_mm2.uncertainty, truth.area_on_base_mm2, m.volume_mm3.value, m.volume_mm3.uncertainty,
      std::abs(truth.volume_mm3), m.reference.residual_rms_mm);
  EXPECT_EQ(m.cavity, c.lesion.height_mm < 0.0) << c.name;
  EXPECT_GT(m.peak_mm.uncertainty, 0.0) << c.name;
  EXPECT_GT(m.area_mm2.uncertainty, 0.0) << c.name;
  return {m.peak_mm.value - std::abs(truth.peak_mm),
          m.area_mm2.value / truth.area_on_base_mm2 - 1.0,
          m.volume_mm3.value / std::abs(truth.volume_mm3) - 1.0};
}

TEST(SimulatedLesionTest, MeetsTheAcceptanceOnASmoothCheekAtTheRigsSampling) {
  const auto cheek = std::make_shared<simulator::BallSurface>(simulator::BallParams{
      .centre_mm = {0.0, 0.0, -60.0}, .radius_mm = 160.0, .cut_below_z_mm = 0.0});
  for (const Case& c : kThesisCases) {
    SCOPED_TRACE(c.name);
    const Errors e = MeasureCase(cheek, c);
    EXPECT_LT(std::abs(e.peak_mm), kPeakTolerance);
    EXPECT_LT(std::abs(e.area_relative), kAreaRelativeTolerance);
    EXPECT_LT(std::abs(e.volume_relative), kVolumeRelativeTolerance);
  }
}

// The thesis's cheek cavity (half-depth contour 11.5 mm in radius) is crossed
// by about four stripes 5.7 mm apart. Cut linearly between stripes, the
// level's contour runs inside the true one and the area falls short; cut
// through the cubic across the stripes (StripeField) it follows the profile
// better. Noise-free samples, five placements across the stripes (every
// 1.14 mm in x): the cubic's area error is smaller at every placement
// (measured -1.5..+0.3 % since 2026-11-27, -1.8..+0.3 % with the earlier
// per-edge cubic; linear -2.6..-0.7 %). Without stripe labels the cut is
// linear.
TEST(SimulatedLesionTest, TheLevelBetweenStripesFollowsTheProfile) {
  const auto cheek = std::make_shared<simulator::BallSurface>(simulator::BallParams{
      .centre_mm = {0.0, 0.0, -60.0}, .radius_mm = 160.0, .cut_below_z_mm = 0.0});
  double worst_linear = 0.0;
  for (int shift = 0; shift < 5; ++shift) {
    simulator::LesionParams lesion = kThesisCases[2].lesion;
    lesion.centre_xy_mm.x() += 1.14 * shift;
    SCOPED_TRACE("centre x " + std::to_string(lesion.centre_xy_mm.x()));
    const auto decorated = std::make_shared<simulator::LesionSurface>(cheek, std::vector{lesion});
    testing::StripeSampling stripes;
    stripes.side = pattern::Side::kRight;
    geometry::SurfaceMesh mesh = testing::SampleStripes(*decorated, stripes);
    const LesionMeasureParams params;
    const double truth = decorated->Truth(0, params.level_fraction).area_on_base_mm2;
    const Polygon2d region = testing::Circle(lesion.centre_xy_mm, lesion.radius_mm + 2.0);
    const double cubic = MeasureLesion(SurfaceQuery(mesh), region, params).area_mm2.value;
    mesh.line.clear();
    const double linear = MeasureLesion(SurfaceQuery(mesh), region, params).area_mm2.value;
    std::printf("cheek cavity at x %+.2f: area cubic %.1f, linear %.1f (true %.1f) mm^2\n",
                lesion.centre_xy_mm.x(), cubic, linear, truth);
    EXPECT_LT(std::abs(cubic / truth - 1.0), 0.02);
    EXPECT_LT(std::abs(cubic / truth - 1.0), std::abs(linear / truth - 1.0));
    worst_linear = std::max(worst_linear, std::abs(linear / truth - 1.0));
  }
  EXPECT_GT(worst_linear, 0.02);
}

TEST(SimulatedLesionTest, MeasuresTheLesionsOnTheStripeSampledFace) {
  const auto face = Face();
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    const Errors e = MeasureCase(face, c);
    EXPECT_LT(std::abs(e.peak_mm), kFacePeakTolerance);
    EXPECT_LT(std::abs(e.area_relative), kFaceAreaRelativeTolerance);
    EXPECT_LT(std::abs(e.volume_relative), kFaceVolumeRelativeTolerance);
  }
}

TEST(SimulatedLesionTest, ACubicReferenceFitsTheCheekBetterThanAQuadricOrAPlane) {
  const Case& c = kCases[0];
  const auto decorated = std::make_shared<simulator::LesionSurface>(Face(), std::vector{c.lesion});
  const geometry::SurfaceMesh mesh = testing::SampleStripes(*decorated, {});
  const SurfaceQuery surface(mesh);
  const Polygon2d region = testing::Circle(c.lesion.centre_xy_mm, c.lesion.radius_mm + 2.0);
  LesionMeasureParams plane, quadric;
  plane.reference = ReferenceKind::kPlane;
  quadric.reference = ReferenceKind::kQuadric;
  const LesionMeasurement with_plane = MeasureLesion(surface, region, plane);
  const LesionMeasurement with_quadric = MeasureLesion(surface, region, quadric);
  const LesionMeasurement with_cubic = MeasureLesion(surface, region, {});
  std::printf(
      "ring RMS: plane %.3f, quadric %.3f, cubic %.3f mm; height error: plane %.2f, "
      "quadric %.2f, cubic %.2f mm\n",
      with_plane.reference.residual_rms_mm, with_quadric.reference.residual_rms_mm,
      with_cubic.reference.residual_rms_mm, with_plane.peak_mm.value - c.lesion.height_mm,
      with_quadric.peak_mm.value - c.lesion.height_mm,
      with_cubic.peak_mm.value - c.lesion.height_mm);
  EXPECT_LT(with_cubic.reference.residual_rms_mm, with_quadric.reference.residual_rms_mm);
  EXPECT_LT(with_quadric.reference.residual_rms_mm, with_plane.reference.residual_rms_mm);
  const std::string table = FormatTable(Rows(with_cubic));
  EXPECT_NE(table.find("lump height"), std::string::npos);
  EXPECT_EQ(ToJson(with_cubic)["kind"], "lump");
}

// `mesh` without the faces whose x-y centroid `drop` selects (a hole where
// stripes were lost).
geometry::SurfaceMesh WithoutFaces(geometry::SurfaceMesh mesh,
                                   const std::function<bool(const Eigen::Vector2d&)>& drop) {
  std::vector<Eigen::Vector3i> kept;
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector2d centroid =
        (mesh.positions[f[0]] + mesh.positions[f[1]] + mesh.positions[f[2]]).head<2>() / 3.0;
    if (!drop(centroid)) kept.push_back(f);
  }
  mesh.faces = kept;
  return mesh;
}

// Relative errors of a measurement's area and volume, measured and filled.
struct Relative {
  double area_measured, area_filled, volume_measured, volume_filled;
};

// The errors of `m` against `truth`, printed under `what`.
Relative RelativeErrors(const char* what, const LesionMeasurement& m,
                        const simulator::LesionTruth& truth) {
  const double area = truth.area_on_base_mm2, volume = std::abs(truth.volume_mm3);
  const Relative e{m.area_mm2.value / area - 1.0, m.filled_area_mm2.value / area - 1.0,
                   m.volume_mm3.value / volume - 1.0, m.filled_volume_mm3.value / volume - 1.0};
  std::printf(
      "%s: area measured %+.1f %%, filled %+.1f +- %.1f %% (%.1f %% of the region "
      "interpolated); volume measured %+.1f %%, filled %+.1f %%\n",
      what, 100.0 * e.area_measured, 100.0 * e.area_filled,
      100.0 * m.filled_area_mm2.uncertainty / area, 100.0 * m.filled_share,
      100.0 * e.volume_measured, 100.0 * e.volume_filled);
  return e;
}

// Stripes lost over a stretch across the thesis lump's half-height contour
// (a hole of 16 x 20 mm the surface encloses): the measured area and volume
// miss what lies in it, the filled ones carry the lump's flank across it
// (thin plate) and say how much was interpolated.
TEST(SimulatedLesionTest, HolesInTheRegionAreFilledAndFlagged) {
  const auto cheek = std::make_shared<simulator::BallSurface>(simulator::BallParams{
      .centre_mm = {0.0, 0.0, -60.0}, .radius_mm = 160.0, .cut_below_z_mm = 0.0});
  const Case& c = kThesisCases[0];
  const auto decorated = std::make_shared<simulator::LesionSurface>(cheek, std::vector{c.lesion});
  testing::StripeSampling stripes;
  stripes.side = c.side;
  stripes.noise_mm = kNoiseMm;
  const geometry::SurfaceMesh whole = testing::SampleStripes(*decorated, stripes);
  const LesionMeasureParams params;
  const simulator::LesionTruth truth = decorated->Truth(0, params.level_fraction);
  const Eigen::Vector2d centre = c.lesion.centre_xy_mm;
  const Polygon2d region = testing::Circle(centre, c.lesion.radius_mm + 2.0);
  const double region_xy = std::numbers::pi * std::pow(c.lesion.radius_mm + 2.0, 2);

  const LesionMeasurement intact = MeasureLesion(SurfaceQuery(whole), region, params);
  EXPECT_EQ(intact.filled_share, 0.0);
  EXPECT_EQ(intact.filled_area_mm2.value, intact.area_mm2.value);
  EXPECT_EQ(intact.filled_volume_mm3.value, intact.volume_mm3.value);

  const Eigen::Vector2d hole_centre = centre + Eigen::Vector2d(0.0, -22.0);
  const geometry::SurfaceMesh holed_mesh = WithoutFaces(whole, [&](const Eigen::Vector2d& xy) {
    return std::abs(xy.x() - hole_centre.x()) < 8.0 && std::abs(xy.y() - hole_centre.y()) < 10.0;
  });
  const SurfaceQuery holed(holed_mesh);
  const LesionMeasurement m = MeasureLesion(holed, region, params);
  const Relative hole = RelativeErrors("hole", m, truth);
  EXPECT_LT(hole.area_measured, -0.05);  // the hole matters
  EXPECT_LT(std::abs(hole.area_filled), kAreaRelativeTolerance);
  EXPECT_LT(std::abs(hole.volume_filled), kVolumeRelativeTolerance);
  EXPECT_NEAR(m.filled_share * region_xy, 16.0 * 20.0, 60.0);  // the hole, but a few cells
  EXPECT_GT(m.filled_area_mm2.uncertainty, m.area_mm2.uncertainty);
  EXPECT_EQ(ToJson(m)["holes_filled"]["share_of_region"], m.filled_share);
  EXPECT_NE(FormatTable(Rows(m)).find("lump area, holes filled"), std::string::npos);

  // Everything beyond x = centre - 10 mm gone (the face's outline crossing
  // the lump: a third of the region, the level contour's outer half): the
  // hole reaches the region's boundary, beyond which the face is taken as
  // undisturbed (d = 0), and is filled between the lump's flank and there;
  // a wider spread says the guess is rougher.
  const geometry::SurfaceMesh cut_mesh =
      WithoutFaces(whole, [&](const Eigen::Vector2d& xy) { return xy.x() < centre.x() - 10.0; });
  const SurfaceQuery cut(cut_mesh);
  const LesionMeasurement edge = MeasureLesion(cut, region, params);
  const Relative open = RelativeErrors("open to the region's boundary", edge, truth);
  EXPECT_LT(edge.surface_coverage, 0.75);
  EXPECT_LT(open.area_measured, -0.2);
  EXPECT_LT(std::abs(open.area_filled), kAreaRelativeTolerance);
  EXPECT_LT(std::abs(open.volume_filled), kVolumeRelativeTolerance);
  EXPECT_NEAR(edge.filled_share, 1.0 - edge.surface_coverage, 0.02);
  EXPECT_GT(edge.filled_area_mm2.uncertainty, m.filled_area_mm2.uncertainty);
}

TEST(SimulatedLesionTest, RejectsARegionWithoutSurface) {
  const auto decorated =
      std::make_shared<simulator::LesionSurface>(Face(), std::vector{kCases[0].lesion});
  const geometry::SurfaceMesh mesh = testing::SampleStripes(*decorated, {});
  const SurfaceQuery surface(mesh);
  EXPECT_THROW(MeasureLesion(surface, testing::Circle({400.0, 0.0}, 10.0)), MeasurementError);
  LesionMeasureParams bad;
  bad.level_fraction = 1.5;
  EXPECT_THROW(MeasureLesion(surface, testing::Circle(kCases[0].lesion.centre_xy_mm, 20.0), bad),
               MeasurementError);
}

}  // namespace
}  // namespace bsls::measurement
