// Cubic B-spline interpolation (thesis Appendix B).
#include "bsls/reconstruction/bspline.h"

#include <gtest/gtest.h>

#include <cmath>

namespace bsls::reconstruction {
namespace {

constexpr double kExact = 1e-9;  // linear algebra on a handful of knots: rounding only

TEST(CubicBSpline, BlendIsAPartitionOfUnity) {
  for (double x = 0.0; x < 1.0; x += 0.05) {
    double sum = 0.0;
    for (int i = -2; i <= 2; ++i) sum += CubicBSplineBlend(x - i);
    EXPECT_NEAR(sum, 1.0, kExact) << x;
  }
  EXPECT_DOUBLE_EQ(CubicBSplineBlend(0.0), 4.0 / 6.0);
  EXPECT_DOUBLE_EQ(CubicBSplineBlend(1.0), 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(CubicBSplineBlend(2.5), 0.0);
}

TEST(CubicBSpline, PassesThroughTheKnots) {
  const std::vector<double> knots = {3.0, -1.0, 4.0, 1.5, 9.0, 2.0};
  const auto spline = CubicBSpline::Interpolate(knots);
  ASSERT_TRUE(spline);
  EXPECT_EQ(spline->intervals(), 5);
  for (std::size_t j = 0; j < knots.size(); ++j) EXPECT_NEAR((*spline)(j), knots[j], kExact);
}

TEST(CubicBSpline, ReproducesStraightLines) {
  const std::vector<double> knots = {2.0, 2.5, 3.0, 3.5};
  const auto spline = CubicBSpline::Interpolate(knots);
  ASSERT_TRUE(spline);
  for (double tau = 0.0; tau <= 3.0; tau += 0.1)
    EXPECT_NEAR((*spline)(tau), 2.0 + 0.5 * tau, kExact);
  // Two knots: the straight line between them.
  const auto two = CubicBSpline::Interpolate({1.0, 4.0});
  ASSERT_TRUE(two);
  EXPECT_NEAR((*two)(0.25), 1.75, kExact);
}

// With the exact end gradients (clamped ends, eq. B.10-B.11) a cubic is
// reproduced exactly: it is a cubic spline through the knots itself.
TEST(CubicBSpline, ClampedEndsReproduceACubic) {
  const auto f = [](double t) { return 0.3 * t * t * t - t * t + 2.0 * t - 1.0; };
  const auto df = [](double t) { return 0.9 * t * t - 2.0 * t + 2.0; };
  std::vector<double> knots;
  for (int j = 0; j <= 4; ++j) knots.push_back(f(j));
  const auto spline = CubicBSpline::Interpolate(knots, df(0.0), df(4.0));
  ASSERT_TRUE(spline);
  for (double tau = 0.0; tau <= 4.0; tau += 0.125) EXPECT_NEAR((*spline)(tau), f(tau), 1e-9) << tau;
}

TEST(CubicBSpline, RefusesTooFewOrNonFiniteKnots) {
  EXPECT_FALSE(CubicBSpline::Interpolate({1.0}));
  EXPECT_FALSE(CubicBSpline::Interpolate({1.0, NAN, 2.0}));
}

}  // namespace
}  // namespace bsls::reconstruction
