// Stitching two sides along the reference line, and the seam error.
#include "bsls/joining/stitch.h"

#include <gtest/gtest.h>

#include <cmath>

namespace bsls::joining {
namespace {

constexpr double kAreaTolerance = 1e-6;  // mm^2
constexpr double kExactMm = 1e-9;
constexpr double kLineSpacingMm = 5.0;
constexpr double kStepMm = 0.5;
constexpr int kRows = 81;  // 40 mm of line

// Flat stripes of one side on z = height(x, y): lines p = 0..2 at x = sign * p * spacing,
// triangles between neighbouring lines, counter-clockwise from +z.
geometry::SurfaceMesh FlatSide(double sign, double (*height)(double x, double y)) {
  geometry::SurfaceMesh mesh;
  for (int p = 0; p < 3; ++p) {
    for (int j = 0; j < kRows; ++j) {
      const double x = sign * p * kLineSpacingMm, y = 20.0 - j * kStepMm;
      mesh.positions.emplace_back(x, y, height(x, y));
      mesh.normals.emplace_back(0.0, 0.0, 1.0);
      mesh.line.push_back(p);
    }
  }
  auto add = [&](int a, int b, int c) {
    const Eigen::Vector3d n =
        (mesh.positions[b] - mesh.positions[a]).cross(mesh.positions[c] - mesh.positions[a]);
    if (n.z() >= 0.0)
      mesh.faces.emplace_back(a, b, c);
    else
      mesh.faces.emplace_back(a, c, b);
  };
  for (int p = 0; p + 1 < 3; ++p) {
    for (int j = 0; j + 1 < kRows; ++j) {
      const int a = p * kRows + j, b = (p + 1) * kRows + j;
      add(a, b, b + 1);
      add(a, b + 1, a + 1);
    }
  }
  return mesh;
}

double Flat(double, double) { return 10.0; }
// A 20 mm step down at y < 0 for x > 2 mm (right of the seam).
double Step(double x, double y) { return x > 2.0 && y < 0.0 ? -10.0 : 10.0; }

double Area(const geometry::SurfaceMesh& mesh) {
  double area = 0.0;
  for (const Eigen::Vector3i& f : mesh.faces) {
    area += 0.5 * (mesh.positions[f[1]] - mesh.positions[f[0]])
                      .cross(mesh.positions[f[2]] - mesh.positions[f[0]])
                      .norm();
  }
  return area;
}

TEST(StitchTest, ZipsTheSidesIntoOneSheet) {
  const geometry::SurfaceMesh left = FlatSide(-1.0, Flat), right = FlatSide(1.0, Flat);
  const StitchResult result = StitchAlongReferenceLine(left, right, 0, 3.0, {});
  std::string why;
  ASSERT_TRUE(result.mesh.IsValid(&why)) << why;
  // Right's reference line is dropped: the left's is the seam.
  EXPECT_EQ(result.mesh.VertexCount(), left.VertexCount() + right.VertexCount() - kRows);
  EXPECT_EQ(result.right_vertex_offset, left.VertexCount());
  EXPECT_EQ(result.skipped_zipper_triangles, 0);
  EXPECT_EQ(result.zipper_triangles, 2 * (kRows - 1));
  // One sheet without holes or overlaps: the area of the whole 20 x 40 mm rectangle.
  EXPECT_NEAR(Area(result.mesh), 4.0 * kLineSpacingMm * (kRows - 1) * kStepMm, kAreaTolerance);
  for (const Eigen::Vector3i& f : result.mesh.faces) {
    const Eigen::Vector3d n = (result.mesh.positions[f[1]] - result.mesh.positions[f[0]])
                                  .cross(result.mesh.positions[f[2]] - result.mesh.positions[f[0]]);
    EXPECT_GT(n.z(), 0.0) << "face " << f.transpose() << " is clockwise";
  }
}

TEST(StitchTest, LeavesADepthJumpOpen) {
  const geometry::SurfaceMesh left = FlatSide(-1.0, Flat), right = FlatSide(1.0, Step);
  StitchParams params;
  const StitchResult result = StitchAlongReferenceLine(left, right, 0, 3.0, params);
  EXPECT_GT(result.skipped_zipper_triangles, 0);
  EXPECT_GT(result.zipper_triangles, 0);
  for (int k = result.mesh.faces.size() - result.zipper_triangles;
       k < static_cast<int>(result.mesh.faces.size()); ++k) {
    const Eigen::Vector3i& f = result.mesh.faces[k];
    for (int e = 0; e < 3; ++e) {
      EXPECT_LE((result.mesh.positions[f[e]] - result.mesh.positions[f[(e + 1) % 3]]).norm(),
                params.max_edge_mm);
    }
  }
}

TEST(MeasureSeamTest, IsTheDistanceBetweenTheLines) {
  const geometry::SurfaceMesh left = FlatSide(-1.0, Flat), right = FlatSide(1.0, Flat);
  const StripeCurve a = StripeCurve::FromMesh(left, 0, 3.0);
  const SeamError same = MeasureSeam(a, StripeCurve::FromMesh(right, 0, 3.0), {});
  EXPECT_NEAR(same.rms_mm, 0.0, kExactMm);
  EXPECT_GT(same.samples, 2 * kRows - 6);  // ends of the runs have no partner
  const SeamError apart =
      MeasureSeam(a,
                  StripeCurve::FromMesh(right, 0, 3.0)
                      .Transformed(Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.3))),
                  {});
  EXPECT_NEAR(apart.rms_mm, 0.3, kExactMm);
  EXPECT_NEAR(apart.max_mm, 0.3, kExactMm);
}

}  // namespace
}  // namespace bsls::joining
