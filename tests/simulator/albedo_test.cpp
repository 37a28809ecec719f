#include "bsls/simulator/albedo.h"

#include <gtest/gtest.h>

#include <random>

namespace bsls::simulator {
namespace {

constexpr double kAlbedoTolerance = 1e-12;

TEST(AlbedoField, SmoothVariationStaysWithinItsBoundsAndIsUsed) {
  AlbedoParams params;
  params.base = 0.8;
  params.variation = 0.1;
  const AlbedoField field(params);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coord(-150.0, 150.0);
  double lo = 1.0, hi = 0.0;
  for (int i = 0; i < 5000; ++i) {
    const double a = field.At({coord(rng), coord(rng), coord(rng) / 3.0});
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
  EXPECT_GE(lo, 0.8 * 0.9 - kAlbedoTolerance);
  EXPECT_LE(hi, 0.8 * 1.1 + kAlbedoTolerance);
  EXPECT_GT(hi - lo, 0.05);  // the variation is really there
}

TEST(AlbedoField, IsDeterministicGivenTheSeed) {
  AlbedoParams params;
  params.seed = 42;
  const AlbedoField a(params), b(params);
  params.seed = 43;
  const AlbedoField c(params);
  const Eigen::Vector3d point(12.0, -30.0, 40.0);
  EXPECT_EQ(a.At(point), b.At(point));
  EXPECT_NE(a.At(point), c.At(point));
}

TEST(AlbedoField, PatchesAreDarkInsideAndSoftAtTheEdge) {
  AlbedoParams params;
  params.variation = 0.0;
  AlbedoPatch patch;
  patch.centre_xy_mm = {-30.0, 45.0};
  patch.semi_axis_x_mm = 20.0;
  patch.semi_axis_y_mm = 5.0;
  patch.albedo = 0.3;
  patch.edge_mm = 4.0;
  params.patches = {patch};
  const AlbedoField field(params);
  EXPECT_NEAR(field.At({-30.0, 45.0, 80.0}), 0.3, kAlbedoTolerance);
  EXPECT_NEAR(field.At({-30.0, 60.0, 80.0}), 0.8, kAlbedoTolerance);
  // On the boundary the soft edge is half way; values rise monotonically outwards.
  EXPECT_NEAR(field.At({-10.0, 45.0, 0.0}), 0.55, 1e-9);
  double previous = 0.0;
  for (double x = -30.0; x <= -5.0; x += 0.5) {
    const double a = field.At({x, 45.0, 0.0});
    EXPECT_GE(a, previous - kAlbedoTolerance);
    previous = a;
  }
}

TEST(AlbedoParams, RejectsOutOfRangeFieldsByName) {
  AlbedoParams params;
  params.variation = 1.5;
  std::string error;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("variation"), std::string::npos) << error;
  params = AlbedoParams{};
  params.patches.push_back(AlbedoPatch{});
  params.patches[0].semi_axis_y_mm = 0.0;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("patch 0"), std::string::npos) << error;
  EXPECT_THROW(AlbedoField{params}, std::invalid_argument);
}

}  // namespace
}  // namespace bsls::simulator
