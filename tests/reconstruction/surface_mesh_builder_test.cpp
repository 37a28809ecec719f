// The polygon mesh between neighbouring lines (thesis 5.2.1).
#include "bsls/reconstruction/surface_mesh_builder.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
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

// Thesis 5.2.1's row pairs (the default is stitched strips).
MeshParams RowPairs() {
  MeshParams params;
  params.strips = StripMethod::kRowPairs;
  return params;
}

TEST(BuildSurfaceMesh, PlaneGivesTwoTrianglesPerQuad) {
  MeshReport report;
  const geometry::SurfaceMesh mesh =
      BuildSurfaceMesh(PlaneLines(5, 10), kCamera, RowPairs(), &report);
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
  const geometry::SurfaceMesh mesh = BuildSurfaceMesh(lines, kCamera, RowPairs(), &report);
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
  const geometry::SurfaceMesh mesh = BuildSurfaceMesh(lines, kCamera, RowPairs(), &report);
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
  const geometry::SurfaceMesh mesh = BuildSurfaceMesh(lines, kCamera, RowPairs(), &report);
  // Quads on rows 0-1, 1-2, 2-3 and 6-7, 7-8, 8-9 remain.
  EXPECT_EQ(report.triangles, 6 * 2);
  ExpectFacingCamera(mesh);
}

// Lines on the plane z = 0, kLinePitchMm apart along x, moving
// `shift_per_row` mm in x from row to row; line p covers rows first[p] ..
// first[p] + rows - 1.
std::vector<TriangulatedLine> LeaningLines(const std::vector<int>& first, int rows,
                                           double shift_per_row) {
  std::vector<TriangulatedLine> out;
  for (int p = 0; p < static_cast<int>(first.size()); ++p) {
    TriangulatedLine line{p, {}};
    for (int row = first[p]; row < first[p] + rows; ++row)
      line.vertices.push_back(
          {row, Eigen::Vector3d(-kLinePitchMm * p + shift_per_row * row, -kRowStepMm * row, 0.0),
           0.1f, 0});
    out.push_back(line);
  }
  return out;
}

// The area (mm^2) of the mesh's faces.
double FacesArea(const geometry::SurfaceMesh& mesh) {
  double area = 0.0;
  for (const Eigen::Vector3i& f : mesh.faces)
    area += 0.5 * (mesh.positions[f[1]] - mesh.positions[f[0]])
                      .cross(mesh.positions[f[2]] - mesh.positions[f[0]])
                      .norm();
  return area;
}

MeshParams Stitched() {
  MeshParams params;
  params.strips = StripMethod::kStitched;
  return params;
}

// On upright lines the stitched strips are the row pairs' quads.
TEST(BuildSurfaceMesh, StitchedUprightLinesGiveTheRowPairsSurface) {
  MeshReport rows, stitched;
  const geometry::SurfaceMesh a = BuildSurfaceMesh(PlaneLines(5, 10), kCamera, RowPairs(), &rows);
  const geometry::SurfaceMesh b =
      BuildSurfaceMesh(PlaneLines(5, 10), kCamera, Stitched(), &stitched);
  EXPECT_EQ(stitched.triangles, rows.triangles);
  EXPECT_NEAR(FacesArea(b), FacesArea(a), 1e-9);
  EXPECT_NEAR(FacesArea(b), 4 * kLinePitchMm * 9 * kRowStepMm, 1e-9);
  EXPECT_EQ(stitched.dropped_across + stitched.dropped_along, 0);
  ExpectFacingCamera(b);
  std::string why;
  EXPECT_TRUE(b.IsValid(&why)) << why;
}

// The last row of line p any face uses.
int LastRowUsed(const geometry::SurfaceMesh& mesh, const std::vector<TriangulatedLine>& lines,
                int p) {
  int first_vertex = 0;
  for (int k = 0; k < p; ++k) first_vertex += static_cast<int>(lines[k].vertices.size());
  int last = -1;
  for (const Eigen::Vector3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k)
      if (mesh.line[f[k]] == p) last = std::max(last, lines[p].vertices[f[k] - first_vertex].row);
  return last;
}

// Lines leaning 60 degrees from the image's vertical, line 1 ending 10 rows
// before line 0 (a skirt turning away): line 1's last sample (row 29) faces
// line 0's row 34.5. Row pairs stop at row 29 of line 0; the stitched strip
// goes on to the samples that face line 1's end and fans from it while its
// edges stay within max_stitch_ratio (1.5) of the lines' distance there
// (2.88 mm): to row 38. Every edge between the lines stays that short.
TEST(BuildSurfaceMesh, StitchedStripReachesWhereItsLinesFaceEachOther) {
  const double lean = 60.0 * std::numbers::pi / 180.0;
  std::vector<TriangulatedLine> lines = LeaningLines({0, 0}, 40, -kRowStepMm * std::tan(lean));
  lines[1].vertices.resize(30);
  const geometry::SurfaceMesh rows = BuildSurfaceMesh(lines, kCamera, RowPairs());
  MeshReport report;
  const geometry::SurfaceMesh stitched = BuildSurfaceMesh(lines, kCamera, Stitched(), &report);
  EXPECT_EQ(LastRowUsed(rows, lines, 0), 29);
  EXPECT_EQ(LastRowUsed(stitched, lines, 0), 38);
  const double distance = kLinePitchMm * std::cos(lean);
  for (const Eigen::Vector3i& f : stitched.faces)
    for (int k = 0; k < 3; ++k) {
      const int u = f[k], w = f[(k + 1) % 3];
      if (stitched.line[u] != stitched.line[w]) {
        EXPECT_LE((stitched.positions[u] - stitched.positions[w]).norm(), 1.5 * distance * 1.01);
      }
    }
  ExpectFacingCamera(stitched);
  std::string why;
  EXPECT_TRUE(stitched.IsValid(&why)) << why;
  EXPECT_GT(report.dropped_across, 0);  // the fan stopped
}

// Stitched strips keep the row pairs' rules: nothing across a depth jump
// beside a raised line, nor across missing rows.
TEST(BuildSurfaceMesh, StitchedStripsLeaveDepthJumpsAndGapsOpen) {
  std::vector<TriangulatedLine> raised = PlaneLines(7, 10);
  for (LineVertex& v : raised[3].vertices) v.position.z() += 50.0;
  const geometry::SurfaceMesh jump = BuildSurfaceMesh(raised, kCamera, Stitched());
  EXPECT_EQ(jump.faces.size(), 4u * 9u * 2u);
  for (const Eigen::Vector3i& f : jump.faces)
    for (int k = 0; k < 3; ++k) EXPECT_NE(jump.line[f[k]], 3);

  std::vector<TriangulatedLine> gap = PlaneLines(2, 10);
  gap[1].vertices.erase(gap[1].vertices.begin() + 4, gap[1].vertices.begin() + 6);  // rows 4, 5
  const geometry::SurfaceMesh holed = BuildSurfaceMesh(gap, kCamera, Stitched());
  // No face uses line 1's step from row 3 to row 6; triangles fanning from
  // those two rows over line 0 cover part of the strip beside the gap, and
  // the rest stays open.
  for (const Eigen::Vector3i& f : holed.faces) {
    int lo = 100, hi = -1;
    for (int k = 0; k < 3; ++k)
      if (holed.line[f[k]] == 1) {
        const int row = gap[1].vertices[f[k] - 10].row;
        lo = std::min(lo, row);
        hi = std::max(hi, row);
      }
    EXPECT_FALSE(lo <= 3 && hi >= 6);
  }
  const double quad = kRowStepMm * kLinePitchMm;
  EXPECT_GT(FacesArea(holed), 6 * quad + 1e-9);  // more than the row pairs' six quads
  EXPECT_LT(FacesArea(holed), 9 * quad - 1e-9);  // less than the whole strip
  ExpectFacingCamera(holed);
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
