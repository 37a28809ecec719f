#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <numbers>

#include "bsls/simulator/lesion.h"

namespace bsls::simulator {
namespace {

constexpr double kVolumeRelativeTolerance = 1e-3;  // closed form vs numerical sum
constexpr double kAreaRelativeTolerance = 1e-3;    // polar midpoint rule at 0.2 mm
constexpr double kHitTolerance = 1e-6;             // mm

// Numerical volume of a lesion by the polar midpoint rule.
double NumericalVolume(const LesionParams& lesion) {
  const int n = 4000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double r = (i + 0.5) * lesion.radius_mm / n;
    sum += lesion.ProfileAt(r) * 2.0 * std::numbers::pi * r * lesion.radius_mm / n;
  }
  return sum;
}

TEST(LesionTest, ClosedFormVolumeMatchesTheIntegral) {
  for (const LesionParams& lesion :
       {LesionParams{},
        LesionParams{.height_mm = -10.0, .radius_mm = 15.0, .top_radius_mm = 0.0}}) {
    EXPECT_NEAR(lesion.Volume(), NumericalVolume(lesion),
                kVolumeRelativeTolerance * std::abs(lesion.Volume()));
    EXPECT_NEAR(std::abs(lesion.ProfileAt(lesion.RadiusAtLevel(0.5))),
                0.5 * std::abs(lesion.height_mm), 1e-9);
  }
}

TEST(LesionTest, RaysHitTheDisplacedPlane) {
  const LesionParams lesion{
      .centre_xy_mm = {10.0, 5.0}, .height_mm = 8.0, .radius_mm = 12.0, .top_radius_mm = 3.0};
  const LesionSurface surface(std::make_shared<PlaneSurface>(PlaneSurface::Horizontal(2.0)),
                              {lesion});
  // An oblique ray (as from the projector) onto the skirt and a vertical one
  // onto the top both land on z = 2 + h(x, y).
  for (const Eigen::Vector3d& target :
       {Eigen::Vector3d(16.0, 9.0, 0.0), Eigen::Vector3d(10.5, 5.0, 0.0),
        Eigen::Vector3d(40.0, 0.0, 0.0)}) {
    geometry::Ray ray;
    ray.origin = {0.0, 0.0, 730.0};
    ray.direction = (target - ray.origin).normalized();
    const auto hit = surface.Intersect(ray, std::numeric_limits<double>::infinity());
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->point.z(), 2.0 + lesion.DisplacementAt(hit->point.head<2>()), kHitTolerance);
    EXPECT_GT(hit->normal.z(), 0.0);
  }
  EXPECT_THROW(LesionSurface(nullptr, {lesion}), std::invalid_argument);
  EXPECT_THROW(LesionSurface(std::make_shared<PlaneSurface>(PlaneSurface::Horizontal(0.0)),
                             {lesion, lesion}),
               std::invalid_argument);
}

TEST(LesionTest, TruthOnAFlatBaseIsTheDisc) {
  const LesionParams lesion;
  const LesionSurface surface(std::make_shared<PlaneSurface>(PlaneSurface::Horizontal(0.0)),
                              {lesion});
  const LesionTruth truth = surface.Truth(0, 0.5);
  const double r = lesion.RadiusAtLevel(0.5);
  EXPECT_NEAR(truth.area_on_base_mm2, std::numbers::pi * r * r,
              kAreaRelativeTolerance * truth.area_on_base_mm2);
  EXPECT_GT(truth.area_on_lesion_mm2, truth.area_on_base_mm2);
  EXPECT_DOUBLE_EQ(truth.volume_mm3, lesion.Volume());
  std::string why;
  EXPECT_FALSE((LesionParams{.top_radius_mm = 40.0}).IsValid(&why));
  EXPECT_NE(why.find("top_radius_mm"), std::string::npos);
}

}  // namespace
}  // namespace bsls::simulator
