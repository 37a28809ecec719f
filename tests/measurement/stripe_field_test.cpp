// The heights between stripes (StripeField, an internal part of the lesion
// measurement) and what they give the level cut: the same area however the
// strips are split into triangles.
#include "stripe_field.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

#include "bsls/measurement/lesion_measure.h"
#include "bsls/testing/surface_sampling.h"

namespace bsls::measurement {
namespace {

constexpr double kPitchMm = 5.7;  // between neighbouring lines, as on the rig at z = 0
constexpr double kStepMm = 0.5;   // along a line

using Height = std::function<double(double x, double y)>;

// Lines p = 0 .. lines-1 at x = x0 + p * kPitchMm, a sample every kStepMm
// in y over [y0, y1], z = height(x, y); each strip (none beside line
// `missing`) made of quads joining samples j, j+1 of line p to samples
// j + shear, j + shear + 1 of line p+1 (shear 0: row pairs), split by the
// diagonal from (p, j) to (p+1, j+shear+1).
geometry::SurfaceMesh Stripes(const Height& height, int lines, double x0, double y0, double y1,
                              int shear = 0, int missing = -1) {
  geometry::SurfaceMesh mesh;
  const int rows = static_cast<int>(std::round((y1 - y0) / kStepMm)) + 1;
  auto index = [&](int p, int j) { return p * rows + j; };
  for (int p = 0; p < lines; ++p)
    for (int j = 0; j < rows; ++j) {
      const double x = x0 + p * kPitchMm, y = y0 + j * kStepMm;
      mesh.positions.emplace_back(x, y, height(x, y));
      mesh.line.push_back(p);
    }
  for (int p = 0; p + 1 < lines; ++p) {
    if (p == missing || p + 1 == missing) continue;
    for (int j = std::max(0, -shear); j + 1 < rows && j + shear + 1 < rows; ++j) {
      const int a0 = index(p, j), a1 = index(p, j + 1), b0 = index(p + 1, j + shear),
                b1 = index(p + 1, j + shear + 1);
      // Counter-clockwise from +z: x grows with p, y with j.
      mesh.faces.emplace_back(a0, b0, b1);
      mesh.faces.emplace_back(a0, b1, a1);
    }
  }
  return mesh;
}

std::vector<int> AllFaces(const geometry::SurfaceMesh& mesh) {
  std::vector<int> faces(mesh.faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) faces[f] = static_cast<int>(f);
  return faces;
}

TEST(StripeField, ReproducesAQuadraticAcrossTheStripes) {
  const Height quadratic = [](double x, double y) { return 0.04 * x * x - 0.01 * x * y + 0.2 * y; };
  const geometry::SurfaceMesh mesh = Stripes(quadratic, 6, 0.0, 0.0, 20.0);
  const SurfaceQuery surface(mesh);
  const internal::StripeField field(mesh, AllFaces(mesh));
  ASSERT_FALSE(field.empty());
  EXPECT_NEAR(std::abs(field.along().y()), 1.0, 1e-12);
  double worst_field = 0.0, worst_linear = 0.0;
  // Between lines 1 and 4, where each bracket has a neighbour on both sides.
  for (double x = kPitchMm + 0.3; x < 4.0 * kPitchMm; x += 0.7)
    for (double y = 0.2; y < 20.0; y += 1.3) {
      const std::optional<double> z = field.Z({x, y});
      ASSERT_TRUE(z.has_value()) << x << ", " << y;
      worst_field = std::max(worst_field, std::abs(*z - quadratic(x, y)));
      worst_linear =
          std::max(worst_linear, std::abs(surface.Above({x, y})->position.z() - quadratic(x, y)));
    }
  EXPECT_LT(worst_field, 1e-9);
  EXPECT_GT(worst_linear, 0.1);  // the flat triangles' chord: 0.04 * 5.7^2 / 4
  // On a line the field is the line's own height.
  EXPECT_NEAR(*field.Z({2.0 * kPitchMm, 7.25}), quadratic(2.0 * kPitchMm, 7.25), 1e-12);
}

// A joined face: the left side's lines 3, 2, 1, 0 and the right side's 1,
// 2, 3 (labels count outwards from the reference line on both sides, and
// the join keeps the left's line 0): the cubic carries over the seam.
TEST(StripeField, CarriesTheCubicOverTheReferenceLineOfAJoinedFace) {
  const Height quadratic = [](double x, double y) { return 0.03 * x * x + 0.02 * x * y + 0.1 * y; };
  geometry::SurfaceMesh mesh = Stripes(quadratic, 7, -3.0 * kPitchMm, 0.0, 20.0);
  for (std::int32_t& line : mesh.line) line = std::abs(line - 3);
  const internal::StripeField field(mesh, AllFaces(mesh));
  for (double x = -1.5 * kPitchMm; x < 1.5 * kPitchMm; x += 0.9)
    for (double y = 0.4; y < 20.0; y += 3.1) {
      const std::optional<double> z = field.Z({x, y});
      ASSERT_TRUE(z.has_value()) << x << ", " << y;
      EXPECT_NEAR(*z, quadratic(x, y), 1e-9) << x << ", " << y;
    }
}

TEST(StripeField, SaysNothingWhereNoNeighbouringStripesBracketThePoint) {
  const Height plane = [](double x, double y) { return 1.0 + 0.1 * x + 0.2 * y; };
  const geometry::SurfaceMesh mesh = Stripes(plane, 6, 0.0, 0.0, 20.0, 0, 3);
  const internal::StripeField field(mesh, AllFaces(mesh));
  EXPECT_FALSE(field.Z({-1.0, 5.0}).has_value());            // before the first line
  EXPECT_FALSE(field.Z({5.5 * kPitchMm, 5.0}).has_value());  // after the last
  EXPECT_FALSE(field.Z({kPitchMm, 25.0}).has_value());       // beyond the lines' ends
  EXPECT_FALSE(field.Z({3.0 * kPitchMm, 5.0}).has_value());  // line 3 has no edges
  EXPECT_FALSE(field.Z({2.5 * kPitchMm, 5.0}).has_value());  // lines 2 and 4: labels two apart
  EXPECT_NEAR(*field.Z({0.5 * kPitchMm, 5.0}), plane(0.5 * kPitchMm, 5.0), 1e-12);
  geometry::SurfaceMesh unlabelled = mesh;
  unlabelled.line.clear();
  const internal::StripeField none(unlabelled, AllFaces(unlabelled));
  EXPECT_TRUE(none.empty());
  EXPECT_FALSE(none.Z({0.5 * kPitchMm, 5.0}).has_value());
}

// The thesis's cheek cavity (Table 7.4b: 10 mm deep; a cosine skirt from 7
// to 16 mm) on a plane, sampled by lines kPitchMm apart: the area at half
// depth (true: pi 11.5^2) is the same with row pairs and with strips whose
// quads are sheared by 3 mm (as stitching joins leaning lines) when the
// level follows the stripes; cut through the flat triangles (no stripe
// labels) it is not.
TEST(StripeField, TheLevelCutDoesNotDependOnTheTriangles) {
  const Eigen::Vector2d centre(3.2 * kPitchMm + 1.1, 25.2);
  const Height cavity = [&](double x, double y) {
    const double r = (Eigen::Vector2d(x, y) - centre).norm();
    if (r <= 7.0) return -10.0;
    if (r >= 16.0) return 0.0;
    return -5.0 * (1.0 + std::cos(std::numbers::pi * (r - 7.0) / 9.0));
  };
  const double truth = std::numbers::pi * 11.5 * 11.5;
  const Polygon2d region = testing::Circle(centre, 18.0);
  double area[2][2];  // [labelled][sheared]
  for (const int sheared : {0, 1}) {
    geometry::SurfaceMesh mesh =
        Stripes(cavity, 13, centre.x() - 6.5 * kPitchMm, 0.0, 50.0, sheared * 6);
    area[1][sheared] = MeasureLesion(SurfaceQuery(mesh), region, {}).area_mm2.value;
    mesh.line.clear();
    area[0][sheared] = MeasureLesion(SurfaceQuery(mesh), region, {}).area_mm2.value;
  }
  std::printf(
      "cavity area, true %.1f mm^2 (row pairs / sheared): following the stripes %.1f / "
      "%.1f, flat triangles %.1f / %.1f\n",
      truth, area[1][0], area[1][1], area[0][0], area[0][1]);
  EXPECT_NEAR(area[1][0], area[1][1], 0.001 * truth);
  EXPECT_GT(std::abs(area[0][0] - area[0][1]), 0.003 * truth);  // 0.4 % here
  EXPECT_LT(std::abs(area[1][0] / truth - 1.0), 0.03);
}

}  // namespace
}  // namespace bsls::measurement
