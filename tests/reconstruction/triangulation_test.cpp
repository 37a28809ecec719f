// Triangulation (thesis 2.2-2.3, eq. 2.1-2.18) on the simulator's thesis rig
// and its uncertainty against Monte-Carlo scatter.
#include "bsls/reconstruction/triangulation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "bsls/simulator/scene.h"

namespace bsls::reconstruction {
namespace {

using pattern::Side;

constexpr double kExactMm = 1e-6;  // exact geometry, rounding only
// Relative difference allowed between the propagated sigma and the RMS of
// Monte-Carlo perturbations. With 20000 draws the RMS itself scatters by
// ~0.5 % (1 / sqrt(2N)); first-order propagation adds well under 1 % for
// these sub-pixel errors.
constexpr double kMonteCarloTolerance = 0.03;
constexpr int kMonteCarloDraws = 20000;

simulator::RigParams Rig() { return simulator::RigParams{}; }

TriangulationModel TrueModel(Side side, const UncertaintyParams& uncertainty) {
  const simulator::RigParams rig = Rig();
  const geometry::PinholeModel projector = simulator::MakeProjector(rig);
  TriangulationModel model;
  model.side = side;
  model.geometry = CalibratedGeometry{simulator::MakeCamera(rig, side),
                                      LightPlanesOfProjector(projector, side), projector};
  model.uncertainty = uncertainty;
  return model;
}

// A world point lit by slide point (s, t) at height z on the projector ray.
Eigen::Vector3d LitPoint(const geometry::PinholeModel& projector, const Eigen::Vector2d& st,
                         double z) {
  const geometry::Ray ray = projector.BackProject(st);
  return ray.At((z - ray.origin.z()) / ray.direction.z());
}

class BothSides : public ::testing::TestWithParam<Side> {};

TEST_P(BothSides, LineSampleIsOnRayAndPlane) {
  const Side side = GetParam();
  const Triangulator triangulator(TrueModel(side, {}));
  const auto& geometry = std::get<CalibratedGeometry>(triangulator.model().geometry);
  for (int p : {0, 3, 9}) {
    for (double t : {-10.0, 0.0, 7.5}) {
      const Eigen::Vector3d world =
          LitPoint(*geometry.projector, {pattern::SFromU(side, p), t}, 35.0);
      const auto image = geometry.camera.Project(world);
      ASSERT_TRUE(image);
      const auto point = triangulator.LineSample(p, *image);
      ASSERT_TRUE(point);
      EXPECT_LT((point->position - world).norm(), kExactMm) << "p " << p << " t " << t;
      EXPECT_GT(point->sigma_mm, 0.0);
    }
  }
}

TEST_P(BothSides, Equation218RecoversJunction) {
  const Side side = GetParam();
  const Triangulator triangulator(TrueModel(side, {}));
  const auto& geometry = std::get<CalibratedGeometry>(triangulator.model().geometry);
  ASSERT_TRUE(triangulator.HasProjector());
  for (int p : {0, 2, 8}) {
    for (int q : {-12, 0, 6}) {
      const Eigen::Vector2d st = calibration::SlideOfJunction(side, p, q);
      const Eigen::Vector3d world = LitPoint(*geometry.projector, st, 60.0);
      const auto image = geometry.camera.Project(world);
      ASSERT_TRUE(image);
      const auto direct =
          IntersectCameraAndProjectorRays(geometry.camera, *image, *geometry.projector, st);
      ASSERT_TRUE(direct);
      EXPECT_LT((*direct - world).norm(), kExactMm);
      const auto junction = triangulator.Junction(p, q, *image, /*q_is_slide_row=*/true);
      ASSERT_TRUE(junction);
      EXPECT_LT((junction->position - world).norm(), kExactMm);
      // Relative q: the plane of p instead, still exact for a true image point.
      const auto by_plane = triangulator.Junction(p, q + 2, *image, false);
      ASSERT_TRUE(by_plane);
      EXPECT_LT((by_plane->position - world).norm(), kExactMm);
    }
  }
}

// Eq. 2.18 with skew rays: the solution is the point nearest both rays, so
// it lies between them (its distances to the two rays add up to their gap).
TEST(Equation218, SkewRaysGiveThePointBetweenThem) {
  const simulator::RigParams rig = Rig();
  const geometry::PinholeModel camera = simulator::MakeCamera(rig, Side::kLeft);
  const geometry::PinholeModel projector = simulator::MakeProjector(rig);
  const Eigen::Vector2d st(-3.0, 4.0);
  const Eigen::Vector3d world = LitPoint(projector, st, 20.0);
  const Eigen::Vector2d image = *camera.Project(world) + Eigen::Vector2d(0.0, 2.0);  // off by 2 px
  const auto x = IntersectCameraAndProjectorRays(camera, image, projector, st);
  ASSERT_TRUE(x);
  const auto distance = [](const geometry::Ray& ray, const Eigen::Vector3d& point) {
    const Eigen::Vector3d d = point - ray.origin;
    return (d - d.dot(ray.direction) * ray.direction).norm();
  };
  const geometry::Ray a = camera.BackProject(image), b = projector.BackProject(st);
  const Eigen::Vector3d n = a.direction.cross(b.direction).normalized();
  const double gap = std::abs((b.origin - a.origin).dot(n));
  EXPECT_NEAR(distance(a, *x) + distance(b, *x), gap, 0.02 * gap);
  EXPECT_GT(gap, 0.1);  // the rays really are skew
}

// The propagated sigma of a line sample equals the RMS 3-D scatter of the
// point under the same random errors (image row, image axes, plane offset).
TEST_P(BothSides, LineSampleSigmaMatchesMonteCarlo) {
  const Side side = GetParam();
  UncertaintyParams u;
  u.stripe_centre_sigma_px = 0.15;
  u.camera_reprojection_sigma_px = 0.1;
  u.light_plane_sigma_mm = 0.08;
  const Triangulator triangulator(TrueModel(side, u));
  const auto& geometry = std::get<CalibratedGeometry>(triangulator.model().geometry);
  std::mt19937 rng(17);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int p : {1, 7}) {
    const Eigen::Vector3d world =
        LitPoint(*geometry.projector, {pattern::SFromU(side, p), 5.0}, 80.0);
    const Eigen::Vector2d image = *geometry.camera.Project(world);
    const auto point = triangulator.LineSample(p, image);
    ASSERT_TRUE(point);
    const calibration::LightPlane plane = *geometry.light_plane(p);
    double sum = 0.0;
    for (int i = 0; i < kMonteCarloDraws; ++i) {
      const double dx =
          std::hypot(u.stripe_centre_sigma_px, u.camera_reprojection_sigma_px) * normal(rng);
      const double dy = u.camera_reprojection_sigma_px * normal(rng);
      calibration::LightPlane moved = plane;
      moved.offset_mm += u.light_plane_sigma_mm * normal(rng);
      const auto x = moved.Intersect(geometry.camera.BackProject(image + Eigen::Vector2d(dx, dy)));
      ASSERT_TRUE(x);
      sum += (*x - point->position).squaredNorm();
    }
    const double rms = std::sqrt(sum / kMonteCarloDraws);
    EXPECT_NEAR(point->sigma_mm / rms, 1.0, kMonteCarloTolerance)
        << "p " << p << ": propagated " << point->sigma_mm << " mm, Monte Carlo " << rms;
  }
}

// The same for a junction by eq. 2.18 (image and slide errors).
TEST_P(BothSides, JunctionSigmaMatchesMonteCarlo) {
  const Side side = GetParam();
  UncertaintyParams u;
  u.junction_sigma_px = 0.2;
  u.camera_reprojection_sigma_px = 0.1;
  u.projector_residual_sigma_d = 0.01;
  const Triangulator triangulator(TrueModel(side, u));
  const auto& geometry = std::get<CalibratedGeometry>(triangulator.model().geometry);
  const int p = 4, q = -6;
  const Eigen::Vector2d st = calibration::SlideOfJunction(side, p, q);
  const Eigen::Vector3d world = LitPoint(*geometry.projector, st, 50.0);
  const Eigen::Vector2d image = *geometry.camera.Project(world);
  const auto point = triangulator.Junction(p, q, image, true);
  ASSERT_TRUE(point);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double image_sigma = std::hypot(u.junction_sigma_px, u.camera_reprojection_sigma_px);
  double sum = 0.0;
  for (int i = 0; i < kMonteCarloDraws; ++i) {
    const Eigen::Vector2d di(image_sigma * normal(rng), image_sigma * normal(rng));
    const Eigen::Vector2d ds(u.projector_residual_sigma_d * normal(rng),
                             u.projector_residual_sigma_d * normal(rng));
    const auto x =
        IntersectCameraAndProjectorRays(geometry.camera, image + di, *geometry.projector, st + ds);
    ASSERT_TRUE(x);
    sum += (*x - point->position).squaredNorm();
  }
  const double rms = std::sqrt(sum / kMonteCarloDraws);
  EXPECT_NEAR(point->sigma_mm / rms, 1.0, kMonteCarloTolerance)
      << "propagated " << point->sigma_mm << " mm, Monte Carlo " << rms;
}

// The thesis formula (eq. 2.1-2.12) is exact on its own set-up: a camera at
// (-+dcp, 0, dc) tilted by theta and a projector at (0, 0, dp) looking down.
TEST_P(BothSides, HeightFormulaIsExactOnItsSetup) {
  const Side side = GetParam();
  GeometricSetupParams setup;
  setup.camera_angle_deg = 33.0;
  setup.camera_k1 = -0.05;
  setup.projector_slide_distance_mm = 102.4;  // 128 d of 0.8 mm
  const geometry::PinholeModel camera = CameraOfSetup(setup, side);
  simulator::RigParams rig;
  rig.projector_centre_mm = {0.0, 0.0, setup.projector_distance_mm};
  rig.projector_focal_d = setup.projector_slide_distance_mm / setup.slide_pitch_mm;
  const geometry::PinholeModel projector = simulator::MakeProjector(rig);
  TriangulationModel model;
  model.side = side;
  model.geometry = setup;
  const Triangulator triangulator(model);
  EXPECT_LT((triangulator.CameraCentre() - camera.Centre()).norm(), kExactMm);
  for (int p : {0, 4, 11}) {
    const Eigen::Vector3d world = LitPoint(projector, {pattern::SFromU(side, p), -6.0}, 42.0);
    const auto image = camera.Project(world);
    ASSERT_TRUE(image);
    const auto h = GeometricHeightPoint(setup, side, *image, p);
    ASSERT_TRUE(h);
    EXPECT_LT((*h - world).norm(), 1e-5) << "p " << p;
    const auto sample = triangulator.LineSample(p, *image);
    ASSERT_TRUE(sample);
    EXPECT_LT((sample->position - world).norm(), 1e-5);
  }
  // Eq. 2.1: on the reference line, height = dc x_l / (x_l + dcp) with x_l
  // the shift on the base plane, whatever the rest of the set-up.
  const Eigen::Vector3d world = LitPoint(projector, {0.0, 0.0}, 25.0);
  const auto h = GeometricHeightPoint(setup, side, *camera.Project(world), 0);
  ASSERT_TRUE(h);
  EXPECT_NEAR(h->z(), 25.0, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Sides, BothSides, ::testing::Values(Side::kLeft, Side::kRight),
                         [](const auto& test_info) {
                           return std::string(pattern::ToString(test_info.param));
                         });

TEST(TriangulationModel, InvalidInputsAreNamed) {
  TriangulationModel model;  // calibrated geometry without a light-plane function
  std::string why;
  EXPECT_FALSE(model.IsValid(&why));
  EXPECT_NE(why.find("light-plane"), std::string::npos) << why;
  EXPECT_THROW(Triangulator{model}, std::invalid_argument);
  model.geometry = GeometricSetupParams{.camera_distance_mm = -1.0};
  EXPECT_FALSE(model.IsValid(&why));
  EXPECT_NE(why.find("camera_distance_mm"), std::string::npos) << why;
  model.geometry = GeometricSetupParams{};
  model.uncertainty.light_plane_sigma_mm = -0.1;
  EXPECT_FALSE(model.IsValid(&why));
  EXPECT_NE(why.find("light_plane_sigma_mm"), std::string::npos) << why;
}

TEST(TriangulationModel, UnknownLineIsNoPoint) {
  TriangulationModel model = TrueModel(Side::kLeft, {});
  auto& geometry = std::get<CalibratedGeometry>(model.geometry);
  geometry.light_plane = [](int) { return std::optional<calibration::LightPlane>(); };
  const Triangulator triangulator(model);
  EXPECT_FALSE(triangulator.LineSample(3, {200.0, 200.0}));
}

}  // namespace
}  // namespace bsls::reconstruction
