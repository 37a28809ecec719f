// The polygon mesh between neighbouring lines (thesis 5.2.1).
#include "bsls/reconstruction/surface_mesh_builder.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <set>

namespace bsls::reconstruction {
namespace {

const Eigen::Vector3d kCamera(-240.0, 0.0, 340.0);
constexpr double kLinePitchMm = 5.7;
constexpr double kRowStepMm = 0.45;

// Lines 0..lines-1 on the plane z = 0 (left side: p towards -x), rows 0..rows-1.
std::vector<TriangulatedLine> PlaneLines(int lines, int rows) {
  std::vector<TriangulatedLine> out;
  for (int p = 0; p < lines; ++p) {
    TriangulatedLine line{p, {}};
    for (int row = 0; row < rows; ++row)
      line.vertices.push_back(
          {row, Eigen::Vector3d(-kLinePitchMm * p, -kRowStepMm * row, 0.0), 0.1f, 0});
    out.push_back(line);
  }
  return out;
}

// Every face counter-clockwise seen from the camera, i.e. its normal towards it.
void ExpectFacingCamera(const geometry::SurfaceMesh& mesh) {
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d n = (mesh.positions[f[1]] - mesh.positions[f[0]])
                                  .cross(mesh.positions[f[2]] - mesh.positions[f[0]]);
    EXPECT_GT(n.dot(kCamera - mesh.positions[f[0]]), 0.0);
  }
}

TEST(BuildSurfaceMesh, PlaneGivesTwoTrianglesPerQuad) {
  MeshReport report;
  const geometry::SurfaceMesh mesh = BuildSurfaceMesh(PlaneLines(5, 10), kCamera, {}, &report);
  std::string why;
  ASSERT_TRUE(mesh.IsValid(&why)) << why;
  EXPECT_EQ(mesh.VertexCount(), 50u);
  EXPECT_EQ(mesh.faces.size(), 4u * 9u * 2u);
  EXPECT_EQ(report.triangles, 72);
  EXPECT_EQ(report.dropped_across + report.dropped_along, 0);
  ExpectFacingCamera(mesh);
  for (const Eigen::Vector3d& n : mesh.normals) EXPECT_NEAR(n.z(), 1.0, 1e-12);
  EXPECT_EQ(mesh.line[12], 1);
  EXPECT_FLOAT_EQ(mesh.uncertainty_mm[0], 0.1f);
}

// A line raised by 50 mm: its strips cross a depth jump on both sides.
TEST(BuildSurfaceMesh, NoTriangleAcrossADepthJump) {
  std::vector<TriangulatedLine> lines = PlaneLines(7, 10);
  for (LineVertex& v : lines[3].vertices) v.position.z() += 50.0;
  MeshReport report;
  const geometry::SurfaceMesh mesh = BuildSurfaceMesh(lines, kCamera, {}, &report);
  for (const Eigen::Vector3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k) EXPECT_NE(mesh.line[f[k]], 3) << "a face uses the raised line";
  EXPECT_EQ(report.triangles, 4 * 9 * 2);  // strips 0-1, 1-2, 4-5 and 5-6 only
  EXPECT_EQ(report.dropped_across, 2 * 9 * 2);
}

// A step of 20 mm along a line between rows 4 and 5: no triangle uses that edge.
TEST(BuildSurfaceMesh, NoTriangleAcrossAJumpAlongALine) {
  std::vector<TriangulatedLine> lines = PlaneLines(3, 10);
  for (TriangulatedLine& line : lines)
    for (LineVertex& v : line.vertices)
      if (v.row >= 5) v.position.z() += 20.0;
  MeshReport report;
  const geometry::SurfaceMesh mesh = BuildSurfaceMesh(lines, kCamera, {}, &report);
  EXPECT_EQ(report.dropped_along, 2);  // one quad per strip
  EXPECT_EQ(report.triangles, 2 * 8 * 2);
  for (const Eigen::Vector3i& f : mesh.faces) {
    std::set<bool> upper;
    for (int k = 0; k < 3; ++k) upper.insert(mesh.positions[f[k]].z() > 10.0);
    EXPECT_EQ(upper.size(), 1u);
  }
}

// Missing rows on a line (a shadow) leave a hole; the rest is meshed.
TEST(BuildSurfaceMesh, GapLeavesAHole) {
  std::vector<TriangulatedLine> lines = PlaneLines(2, 10);
  auto& v = lines[1].vertices;
  v.erase(v.begin() + 4, v.begin() + 6);  // rows 4 and 5
  MeshReport report;
  const geometry::SurfaceMesh mesh = BuildSurfaceMesh(lines, kCamera, {}, &report);
  // Quads on rows 0-1, 1-2, 2-3 and 6-7, 7-8, 8-9 remain.
  EXPECT_EQ(report.triangles, 6 * 2);
  ExpectFacingCamera(mesh);
}

TEST(BuildSurfaceMesh, IsolatedVertexFacesTheCamera) {
  std::vector<TriangulatedLine> lines = PlaneLines(1, 3);
  const geometry::SurfaceMesh mesh = BuildSurfaceMesh(lines, kCamera);
  EXPECT_TRUE(mesh.faces.empty());
  EXPECT_NEAR((mesh.normals[0] - (kCamera - mesh.positions[0]).normalized()).norm(), 0.0, 1e-12);
}

TEST(BuildSurfaceMesh, RefusesUnorderedRowsAndBadParams) {
  std::vector<TriangulatedLine> lines = PlaneLines(2, 4);
  std::swap(lines[0].vertices[1], lines[0].vertices[2]);
  EXPECT_THROW(BuildSurfaceMesh(lines, kCamera), std::invalid_argument);
  MeshParams params;
  params.max_across_ratio = 0.5;
  std::string why;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("max_across_ratio"), std::string::npos);
  EXPECT_THROW(BuildSurfaceMesh(PlaneLines(2, 4), kCamera, params), std::invalid_argument);
}

}  // namespace
}  // namespace bsls::reconstruction
