#include "bsls/geometry/pinhole_model.h"

#include <gtest/gtest.h>

#include <random>

namespace bsls::geometry {
namespace {

constexpr double kPixelTolerance = 1e-9;
constexpr double kRayTolerance = 1e-9;

PinholeModel MakeCamera(double k1, double k2) {
  Intrinsics in;
  in.fx = 950.0;
  in.fy = 950.0;
  in.cx = 255.5;
  in.cy = 255.5;
  in.k1 = k1;
  in.k2 = k2;
  auto pose = Pose::LookAt({-240.0, 0.0, 340.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0});
  EXPECT_TRUE(pose.has_value());
  return PinholeModel(in, *pose);
}

TEST(PinholeModel, LookAtPutsTargetOnPrincipalPoint) {
  const PinholeModel cam = MakeCamera(0.0, 0.0);
  const auto px = cam.Project({0.0, 0.0, 0.0});
  ASSERT_TRUE(px.has_value());
  EXPECT_NEAR(px->x(), 255.5, kPixelTolerance);
  EXPECT_NEAR(px->y(), 255.5, kPixelTolerance);
  // World up (+y) appears towards smaller image y.
  const auto up = cam.Project({0.0, 10.0, 0.0});
  ASSERT_TRUE(up.has_value());
  EXPECT_LT(up->y(), 255.5);
  EXPECT_NEAR(cam.Centre().x(), -240.0, 1e-9);
}

TEST(PinholeModel, ProjectBackProjectRoundTripWithDistortion) {
  const PinholeModel cam = MakeCamera(-0.08, 0.01);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-60.0, 60.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d world(coord(rng), coord(rng), coord(rng) + 60.0);
    const auto px = cam.Project(world);
    ASSERT_TRUE(px.has_value());
    const Ray ray = cam.BackProject(*px);
    // The world point lies on the ray.
    const Eigen::Vector3d to_point = world - ray.origin;
    const double off_ray = (to_point - to_point.dot(ray.direction) * ray.direction).norm();
    EXPECT_LT(off_ray, kRayTolerance * to_point.norm()) << i;
  }
}

TEST(PinholeModel, BehindTheCameraIsNotProjected) {
  const PinholeModel cam = MakeCamera(0.0, 0.0);
  EXPECT_FALSE(cam.Project({-480.0, 0.0, 680.0}).has_value());
}

TEST(PinholeModel, LookAtRejectsDegenerateViews) {
  EXPECT_FALSE(Pose::LookAt({0, 0, 1}, {0, 0, 1}, {0, 1, 0}).has_value());
  EXPECT_FALSE(Pose::LookAt({0, 1, 0}, {0, 0, 0}, {0, 1, 0}).has_value());
}

}  // namespace
}  // namespace bsls::geometry
