#include "bsls/simulator/surface.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace bsls::simulator {
namespace {

constexpr double kDistanceTolerance = 1e-9;  // mm
constexpr double kInfinity = std::numeric_limits<double>::infinity();

geometry::Ray RayFromTo(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  geometry::Ray ray;
  ray.origin = from;
  ray.direction = (to - from).normalized();
  return ray;
}

TEST(PlaneSurface, HitsAtTheRightDistanceFromBothSides) {
  const PlaneSurface plane = PlaneSurface::Horizontal(10.0);
  const auto down = plane.Intersect(RayFromTo({3, 4, 110}, {3, 4, 0}), kInfinity);
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(down->distance, 100.0, kDistanceTolerance);
  EXPECT_NEAR(down->point.z(), 10.0, kDistanceTolerance);
  EXPECT_EQ(down->normal, Eigen::Vector3d::UnitZ());
  const auto up = plane.Intersect(RayFromTo({0, 0, -5}, {1, 1, 20}), kInfinity);
  ASSERT_TRUE(up.has_value());
  EXPECT_NEAR(up->point.z(), 10.0, kDistanceTolerance);
}

TEST(PlaneSurface, RespectsMaxDistanceAndParallelRays) {
  const PlaneSurface plane = PlaneSurface::Horizontal(0.0);
  EXPECT_FALSE(plane.Intersect(RayFromTo({0, 0, 100}, {0, 0, 0}), 99.0).has_value());
  EXPECT_TRUE(plane.Intersect(RayFromTo({0, 0, 100}, {0, 0, 0}), 101.0).has_value());
  EXPECT_FALSE(plane.Intersect(RayFromTo({0, 0, 100}, {1, 0, 100}), kInfinity).has_value());
  EXPECT_FALSE(plane.Intersect(RayFromTo({0, 0, 100}, {0, 0, 200}), kInfinity).has_value());
}

TEST(RampSurface, HitPointsLieOnTheSlopeInsideTheRectangle) {
  RampParams params;
  params.foot_xy_mm = {-120.0, 0.0};
  params.rise_azimuth_deg = 0.0;  // rising towards +x
  params.slope_deg = 45.0;
  params.run_mm = 150.0;
  params.width_mm = 200.0;
  const RampSurface ramp(params);
  // Straight down onto x = -50: height 70 at 45 degrees.
  const auto hit = ramp.Intersect(RayFromTo({-50, 20, 500}, {-50, 20, 0}), kInfinity);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z(), 70.0, kDistanceTolerance);
  EXPECT_NEAR(ramp.PlaneHeightAt(-50.0, 20.0), 70.0, kDistanceTolerance);
  // Front side up, leaning away from the rise direction.
  EXPECT_NEAR(hit->normal.x(), -std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(hit->normal.z(), std::sqrt(0.5), 1e-12);
  // Outside the rectangle: beyond the top edge, before the foot, beside it.
  EXPECT_FALSE(ramp.Intersect(RayFromTo({40, 0, 500}, {40, 0, 0}), kInfinity).has_value());
  EXPECT_FALSE(ramp.Intersect(RayFromTo({-130, 0, 500}, {-130, 0, -100}), kInfinity).has_value());
  EXPECT_FALSE(ramp.Intersect(RayFromTo({-50, 120, 500}, {-50, 120, 0}), kInfinity).has_value());
}

TEST(RampSurface, RejectsInvalidParams) {
  RampParams params;
  params.slope_deg = 90.0;
  std::string error;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("slope_deg"), std::string::npos) << error;
  EXPECT_THROW(RampSurface{params}, std::invalid_argument);
}

TEST(BallSurface, MatchesTheSphereEquationOnRandomRays) {
  BallParams params;
  params.centre_mm = {-70.0, 5.0, -15.0};
  params.radius_mm = 60.0;
  params.cut_below_z_mm = -std::numeric_limits<double>::infinity();
  const BallSurface ball(params);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> offset(-55.0, 55.0);
  int hits = 0;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d target = params.centre_mm + Eigen::Vector3d(offset(rng), offset(rng), 0);
    const auto hit = ball.Intersect(RayFromTo({0, 0, 730}, target), kInfinity);
    if (!hit) continue;
    ++hits;
    EXPECT_NEAR((hit->point - params.centre_mm).norm(), params.radius_mm, 1e-9);
    EXPECT_GT(hit->normal.dot(Eigen::Vector3d(0, 0, 730) - hit->point), 0.0);
  }
  EXPECT_GT(hits, 300);
}

TEST(BallSurface, CutRemovesThePartBelowThePlane) {
  BallParams params;
  params.centre_mm = {0.0, 0.0, 0.0};
  params.radius_mm = 10.0;
  params.cut_below_z_mm = 0.0;
  const BallSurface ball(params);
  // From below, the first sphere point (z = -10) is cut; the ray goes on to the inside of the top.
  const auto hit = ball.Intersect(RayFromTo({0, 0, -100}, {0, 0, 0}), kInfinity);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z(), 10.0, kDistanceTolerance);
  // A ray passing only through the cut part misses.
  EXPECT_FALSE(ball.Intersect(RayFromTo({-100, 0, -5}, {100, 0, -5}), kInfinity).has_value());
}

TEST(CylinderSurface, HitsLieOnTheMantleOrACapAndFaceTheRay) {
  CylinderParams params;
  params.centre_mm = {-50.0, 10.0, 30.0};
  params.axis = {1.0, 1.0, 0.0};
  params.radius_mm = 40.0;
  params.length_mm = 160.0;
  params.cut_below_z_mm = -kInfinity;
  const CylinderSurface cylinder(params);
  const Eigen::Vector3d axis = params.axis.normalized();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> offset(-120.0, 120.0);
  int mantle = 0, caps = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d origin(offset(rng) * 3.0, offset(rng) * 3.0, 400.0 + offset(rng));
    const Eigen::Vector3d target = params.centre_mm + Eigen::Vector3d(offset(rng), offset(rng), 0);
    const auto hit = cylinder.Intersect(RayFromTo(origin, target), kInfinity);
    if (!hit) continue;
    const Eigen::Vector3d rel = hit->point - params.centre_mm;
    const double axial = rel.dot(axis);
    const double radial = (rel - axial * axis).norm();
    EXPECT_LE(std::abs(axial), params.length_mm / 2.0 + kDistanceTolerance);
    EXPECT_LE(radial, params.radius_mm + kDistanceTolerance);
    if (std::abs(radial - params.radius_mm) < 1e-6) {
      ++mantle;
    } else {
      EXPECT_NEAR(std::abs(axial), params.length_mm / 2.0, 1e-6);
      ++caps;
    }
    // The first hit from outside faces the ray's origin.
    EXPECT_GT(hit->normal.dot(origin - hit->point), 0.0);
  }
  EXPECT_GT(mantle, 300);
  EXPECT_GT(caps, 20);
}

TEST(CylinderSurface, CutAndOpenEndsLetRaysThrough) {
  CylinderParams params;
  params.centre_mm = {0.0, 0.0, 0.0};
  params.axis = {0.0, 1.0, 0.0};
  params.radius_mm = 10.0;
  params.length_mm = 50.0;
  params.cut_below_z_mm = 0.0;
  // From straight above: the top of the mantle.
  const CylinderSurface cut(params);
  const auto top = cut.Intersect(RayFromTo({0, 0, 100}, {0, 0, 0}), kInfinity);
  ASSERT_TRUE(top.has_value());
  EXPECT_NEAR(top->point.z(), 10.0, kDistanceTolerance);
  // Below the cut nothing is hit.
  EXPECT_FALSE(cut.Intersect(RayFromTo({-100, 0, -5}, {100, 0, -5}), kInfinity).has_value());
  // Along the axis: the cap closes it; without caps the ray passes through.
  const geometry::Ray along = RayFromTo({0, -100, 5}, {0, 0, 5});
  const auto cap = cut.Intersect(along, kInfinity);
  ASSERT_TRUE(cap.has_value());
  EXPECT_NEAR(cap->point.y(), -25.0, kDistanceTolerance);
  params.caps = false;
  EXPECT_FALSE(CylinderSurface(params).Intersect(along, kInfinity).has_value());
}

TEST(CylinderSurface, RejectsInvalidParams) {
  CylinderParams params;
  params.axis = Eigen::Vector3d::Zero();
  std::string error;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("axis"), std::string::npos);
  params = CylinderParams{};
  params.radius_mm = -1.0;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("radius_mm"), std::string::npos);
  EXPECT_THROW(CylinderSurface{params}, std::invalid_argument);
}

}  // namespace
}  // namespace bsls::simulator
