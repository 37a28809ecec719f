#include "bsls/geometry/curve_fit.h"

#include <gtest/gtest.h>

#include <random>

namespace bsls::geometry {
namespace {

constexpr double kExact = 1e-9;  // exact samples: only rounding

TEST(CurveFit, ALineAndAParabolaThroughExactSamplesAreFound) {
  Samples line, curve;
  for (int t = -4; t <= 5; ++t) {
    line.emplace_back(t, 2.5 - 0.75 * t);
    curve.emplace_back(t, 1.0 + 0.5 * t - 0.125 * t * t);
  }
  double a = 0, b = 0;
  ASSERT_TRUE(FitLine(line, &a, &b));
  EXPECT_NEAR(a, 2.5, kExact);
  EXPECT_NEAR(b, -0.75, kExact);
  Quadratic c{};
  ASSERT_TRUE(FitParabola(curve, &c));
  EXPECT_NEAR(c[0], 1.0, kExact);
  EXPECT_NEAR(c[1], 0.5, kExact);
  EXPECT_NEAR(c[2], -0.125, kExact);
  EXPECT_NEAR(*FitAtZero(curve), 1.0, kExact);
}

TEST(CurveFit, NoisySamplesAverageOut) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.1);
  Samples s;
  for (int t = -50; t <= 50; ++t) s.emplace_back(t, 3.0 + 0.2 * t + noise(rng));
  double a = 0, b = 0;
  ASSERT_TRUE(FitLine(s, &a, &b));
  EXPECT_NEAR(a, 3.0, 0.05);
  EXPECT_NEAR(b, 0.2, 0.002);
}

TEST(CurveFit, TooFewOrDegenerateSamplesGiveNoCurve) {
  double a = 0, b = 0;
  Quadratic c{};
  EXPECT_FALSE(FitLine(Samples{{1.0, 2.0}}, &a, &b));
  EXPECT_FALSE(FitLine(Samples{{1.0, 2.0}, {1.0, 3.0}}, &a, &b));  // one t
  const Samples four{{-1, 1}, {0, 2}, {1, 3}, {2, 4}};
  EXPECT_FALSE(FitParabola(four, &c));
  EXPECT_NEAR(*FitAtZero(four), 2.0, kExact);  // fewer than five: the line
  const Samples two_ts{{0, 1}, {0, 2}, {1, 3}, {1, 4}, {1, 5}};
  EXPECT_FALSE(FitParabola(two_ts, &c));  // two t values fix no parabola
  EXPECT_FALSE(FitAtZero(Samples{}).has_value());
}

}  // namespace
}  // namespace bsls::geometry
