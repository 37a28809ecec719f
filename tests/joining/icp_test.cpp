// The pieces the matching is built from: the ordered stripe curve and its
// closest-point query, the rigid fit of point pairs, ICP on a curve.
#include "bsls/joining/icp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "bsls/joining/stripe_curve.h"

namespace bsls::joining {
namespace {

constexpr double kExactMm = 1e-9;
constexpr double kRecoveredDeg = 1e-3;
constexpr double kRecoveredMm = 1e-3;

double AngleDeg(const Eigen::Matrix3d& r) {
  return Eigen::AngleAxisd(r).angle() * 180.0 / std::numbers::pi;
}

// A curved space curve (not planar: every degree of freedom is pinned).
std::vector<Eigen::Vector3d> Helix(int count, double step) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double s = step * i;
    points.emplace_back(10.0 * std::sin(s / 15.0), 60.0 - s, 20.0 * std::cos(s / 20.0));
  }
  return points;
}

geometry::SurfaceMesh LineMesh(const std::vector<Eigen::Vector3d>& points, int p) {
  geometry::SurfaceMesh mesh;
  for (const Eigen::Vector3d& q : points) {
    mesh.positions.push_back(q);
    mesh.line.push_back(p);
  }
  return mesh;
}

TEST(StripeCurveTest, OrdersTopToBottomAndSplitsAtGaps) {
  geometry::SurfaceMesh mesh = LineMesh({{0, 1, 0}, {0, 3, 0}, {0, 2, 0}, {0, 10, 0}}, 0);
  mesh.positions.emplace_back(5, 2.5, 0);
  mesh.line.push_back(1);  // another line: left out
  const StripeCurve curve = StripeCurve::FromMesh(mesh, 0, 2.0);
  ASSERT_EQ(curve.size(), 4u);
  EXPECT_EQ(curve.vertices(), (std::vector<int>{3, 1, 2, 0}));
  EXPECT_FALSE(curve.Joined(0));  // 10 -> 3: a gap
  EXPECT_TRUE(curve.Joined(1));
  // Across the curve: found, at the foot of the perpendicular.
  const auto inside = curve.Closest({1.0, 2.5, 0.0}, 5.0);
  ASSERT_TRUE(inside);
  EXPECT_NEAR(inside->distance_mm, 1.0, kExactMm);
  EXPECT_NEAR(inside->point.y(), 2.5, kExactMm);
  // Beyond the end of a run (below y = 1, or in the gap above 3): no partner.
  EXPECT_FALSE(curve.Closest({0.0, 0.0, 0.0}, 5.0));
  EXPECT_FALSE(curve.Closest({0.0, 5.0, 0.0}, 5.0));
  // Too far.
  EXPECT_FALSE(curve.Closest({4.0, 2.5, 0.0}, 3.0));
}

TEST(StripeCurveTest, EmptyWithoutLabels) {
  geometry::SurfaceMesh mesh;
  mesh.positions.emplace_back(0, 0, 0);
  EXPECT_TRUE(StripeCurve::FromMesh(mesh, 0, 1.0).empty());
}

TEST(RigidFromPairsTest, RecoversATransformAndRejectsCollinearPairs) {
  const Eigen::Isometry3d truth = Eigen::Translation3d(1.0, -2.0, 3.0) *
                                  Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized());
  const std::vector<Eigen::Vector3d> source = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {3, 4, 5}};
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.push_back(truth * p);
  const auto fitted = RigidFromPairs(source, target);
  ASSERT_TRUE(fitted);
  EXPECT_LT((fitted->matrix() - truth.matrix()).norm(), 1e-9);
  EXPECT_FALSE(
      RigidFromPairs({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}, {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}));
  EXPECT_FALSE(RigidFromPairs({{0, 0, 0}, {1, 0, 0}}, {{0, 0, 0}, {1, 0, 0}}));
}

TEST(AlignToCurveTest, RecoversARigidMotionOfACurve) {
  const std::vector<Eigen::Vector3d> fixed_points = Helix(300, 0.4);
  const StripeCurve fixed = StripeCurve::FromMesh(LineMesh(fixed_points, 0), 0, 1.0);
  const Eigen::Isometry3d motion =
      Eigen::Translation3d(2.0, -1.5, 1.0) *
      Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.2, 1.0, 0.3).normalized());
  std::vector<Eigen::Vector3d> moving;
  for (std::size_t i = 5; i + 5 < fixed_points.size(); ++i)
    moving.push_back(motion * fixed_points[i]);
  const IcpResult result = AlignToCurve(fixed, moving, Eigen::Isometry3d::Identity(), {});
  ASSERT_TRUE(result.converged) << result.failure;
  const Eigen::Isometry3d error = result.transform * motion;
  EXPECT_LT(AngleDeg(error.linear()), kRecoveredDeg);
  EXPECT_LT(error.translation().norm(), kRecoveredMm);
  EXPECT_LT(result.rms_mm, kRecoveredMm);
}

// Every step asks its caller first: stopped at the third question, the
// alignment throws after two steps instead of converging.
TEST(AlignToCurveTest, StopsWhenItsCallerAsks) {
  const std::vector<Eigen::Vector3d> fixed_points = Helix(300, 0.4);
  const StripeCurve fixed = StripeCurve::FromMesh(LineMesh(fixed_points, 0), 0, 1.0);
  const Eigen::Isometry3d motion =
      Eigen::Translation3d(2.0, -1.5, 1.0) * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY());
  std::vector<Eigen::Vector3d> moving;
  for (const Eigen::Vector3d& p : fixed_points) moving.push_back(motion * p);
  int asked = 0;
  const Cancellation third([&asked] { return ++asked >= 3; });
  EXPECT_THROW(AlignToCurve(fixed, moving, Eigen::Isometry3d::Identity(), {}, third), Cancelled);
  EXPECT_EQ(asked, 3);
  // Never asked to stop, the same alignment converges.
  EXPECT_TRUE(
      AlignToCurve(fixed, moving, Eigen::Isometry3d::Identity(), {}, Cancellation()).converged);
}

TEST(AlignToCurveTest, AStraightLineIsDegenerate) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 100; ++i) points.emplace_back(0.0, 50.0 - 0.5 * i, 10.0);
  const StripeCurve fixed = StripeCurve::FromMesh(LineMesh(points, 0), 0, 1.0);
  const IcpResult result =
      AlignToCurve(fixed, points, Eigen::Isometry3d(Eigen::Translation3d(0.5, 0.0, 0.0)), {});
  EXPECT_FALSE(result.converged);
  EXPECT_NE(result.failure.find("degenerate"), std::string::npos) << result.failure;
}

TEST(AlignToCurveTest, ReportsTheIterationCap) {
  const std::vector<Eigen::Vector3d> points = Helix(300, 0.4);
  const StripeCurve fixed = StripeCurve::FromMesh(LineMesh(points, 0), 0, 1.0);
  IcpParams params;
  params.max_iterations = 1;
  const IcpResult result =
      AlignToCurve(fixed, points, Eigen::Isometry3d(Eigen::Translation3d(1.0, 0.5, 0.0)), params);
  EXPECT_FALSE(result.converged);
  EXPECT_EQ(result.iterations, 1);
  EXPECT_NE(result.failure.find("iterations"), std::string::npos) << result.failure;
}

TEST(IcpParamsTest, RejectsOutOfRange) {
  IcpParams params;
  std::string why;
  EXPECT_TRUE(params.IsValid(&why));
  params.trim_fraction = 0.5;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("trim_fraction"), std::string::npos);
  params = {};
  params.curve_weight = 0.0;
  params.plane_weight = 0.0;
  EXPECT_FALSE(params.IsValid(&why));
}

}  // namespace
}  // namespace bsls::joining
