#include "bsls/measurement/geodesic.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bsls/simulator/surface.h"
#include "bsls/testing/surface_sampling.h"

namespace bsls::measurement {
namespace {

// Relative error of the Steiner-graph geodesic against the exact great-circle
// distance on a ball sampled every 1 mm (docs/measurement.md).
constexpr double kBallRelativeTolerance = 0.004;
// Dijkstra on the mesh edges (k = 0) must be clearly worse than that.
constexpr double kEdgePathMinRelativeExcess = 0.02;
constexpr double kPlaneTolerance = 1e-6;  // mm

struct Ball {
  simulator::BallParams params{
      .centre_mm = {0.0, 0.0, -20.0}, .radius_mm = 60.0, .cut_below_z_mm = 0.0};
  geometry::SurfaceMesh mesh;
  Ball() {
    testing::GridSampling grid;
    grid.x_min_mm = grid.y_min_mm = -50.0;
    grid.x_max_mm = grid.y_max_mm = 50.0;
    mesh = testing::SampleGrid(simulator::BallSurface(params), grid);
  }
  // Exact great-circle distance between the ball points over a and b.
  double Exact(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const {
    auto lift = [&](const Eigen::Vector2d& p) {
      const Eigen::Vector2d d = p - params.centre_mm.head<2>();
      return Eigen::Vector3d(d.x(), d.y(),
                             std::sqrt(params.radius_mm * params.radius_mm - d.squaredNorm()));
    };
    const Eigen::Vector3d u = lift(a).normalized(), v = lift(b).normalized();
    return params.radius_mm * std::acos(std::clamp(u.dot(v), -1.0, 1.0));
  }
};

TEST(GeodesicTest, MatchesTheGreatCircleOnABall) {
  const Ball ball;
  const SurfaceQuery surface(ball.mesh);
  const Eigen::Vector2d a(-35.3, -12.2), b(30.1, 21.7);
  const double exact = ball.Exact(a, b);
  const GeodesicResult result = GeodesicDistance(surface, a, b);
  const double relative = (result.distance_mm.value - exact) / exact;
  std::printf(
      "ball geodesic: exact %.3f mm, Steiner k=6 %.3f mm (%+.3f %%), chord %.3f mm, "
      "discretisation estimate %.3f mm\n",
      exact, result.distance_mm.value, 100.0 * relative, result.straight_mm.value,
      result.discretisation_mm);
  EXPECT_LT(std::abs(relative), kBallRelativeTolerance);
  EXPECT_GT(result.distance_mm.value, result.straight_mm.value);
  ASSERT_GE(result.path.size(), 2u);
  EXPECT_NEAR(result.path.front().x(), a.x(), 1e-9);
  EXPECT_NEAR(result.path.back().y(), b.y(), 1e-9);

  GeodesicParams edges_only;
  edges_only.steiner_points_per_edge = 0;
  const double edge_path = GeodesicDistance(surface, a, b, edges_only).distance_mm.value;
  std::printf("ball geodesic: Dijkstra on edges %.3f mm (%+.3f %%)\n", edge_path,
              100.0 * (edge_path - exact) / exact);
  EXPECT_GT((edge_path - exact) / exact, kEdgePathMinRelativeExcess);
}

TEST(GeodesicTest, IsTheStraightLineOnAPlane) {
  const simulator::PlaneSurface plane = simulator::PlaneSurface::Horizontal(5.0);
  testing::GridSampling grid;
  grid.step_x_mm = 3.0;
  grid.step_y_mm = 2.0;
  const geometry::SurfaceMesh mesh = testing::SampleGrid(plane, grid);
  const SurfaceQuery surface(mesh);
  // Along the grid's triangle diagonals (3, 2) the graph holds the straight path.
  const GeodesicResult result = GeodesicDistance(surface, {-29.0, -20.0}, {31.0, 20.0});
  EXPECT_NEAR(result.distance_mm.value, result.straight_mm.value, kPlaneTolerance);
}

TEST(GeodesicTest, RejectsBadInput) {
  const Ball ball;
  const SurfaceQuery surface(ball.mesh);
  GeodesicParams bad;
  bad.steiner_points_per_edge = -1;
  std::string why;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_THROW(GeodesicDistance(surface, {0.0, 0.0}, {1.0, 1.0}, bad), MeasurementError);
  EXPECT_THROW(GeodesicDistance(surface, {0.0, 0.0}, {90.0, 0.0}), MeasurementError);
}

}  // namespace
}  // namespace bsls::measurement
