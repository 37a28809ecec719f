#include "bsls/measurement/measures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "bsls/measurement/report.h"
#include "bsls/measurement/surface_query.h"
#include "bsls/simulator/surface.h"
#include "bsls/testing/surface_sampling.h"

namespace bsls::measurement {
namespace {

constexpr double kExactTolerance = 1e-9;         // mm, mm^2: planar data, no noise
constexpr double kSlopedHeightTolerance = 1e-6;  // mm: a plane is interpolated exactly

// A tilted plane z = 20 + 0.3 x - 0.2 y sampled on a 2 mm grid.
geometry::SurfaceMesh TiltedPlane(double noise_mm = 0.0) {
  const Eigen::Vector3d normal(-0.3, 0.2, 1.0);
  const simulator::PlaneSurface plane(Eigen::Vector3d(0.0, 0.0, 20.0), normal);
  testing::GridSampling grid;
  grid.x_min_mm = -40.0, grid.x_max_mm = 40.0, grid.y_min_mm = -40.0, grid.y_max_mm = 40.0;
  grid.step_x_mm = 2.0, grid.step_y_mm = 2.0;
  grid.noise_mm = noise_mm;
  return testing::SampleGrid(plane, grid);
}

Polygon2d Square(double centre_x, double centre_y, double half) {
  return {{centre_x - half, centre_y - half},
          {centre_x + half, centre_y - half},
          {centre_x + half, centre_y + half},
          {centre_x - half, centre_y + half}};
}

TEST(MeasuresTest, HeightAboveBaseIsTheInterpolatedZ) {
  const geometry::SurfaceMesh mesh = TiltedPlane();
  const SurfaceQuery surface(mesh);
  const Measured h = HeightAboveBase(surface, {3.3, -7.1});
  EXPECT_NEAR(h.value, 20.0 + 0.3 * 3.3 + 0.2 * 7.1, kSlopedHeightTolerance);
  EXPECT_NEAR(h.uncertainty, 0.0, kSlopedHeightTolerance);  // no noise, flat
}

TEST(MeasuresTest, HeightAbovePlaneFittedToTheSamePlaneIsZero) {
  const geometry::SurfaceMesh mesh = TiltedPlane();
  const SurfaceQuery surface(mesh);
  const ReferencePlane plane = FitReferencePlane(surface, Square(0.0, 0.0, 30.0));
  EXPECT_NEAR(plane.residual_rms_mm, 0.0, kExactTolerance);
  EXPECT_NEAR(HeightAbovePlane(surface, {5.0, 5.0}, plane).value, 0.0, kSlopedHeightTolerance);
}

TEST(MeasuresTest, StraightDistanceFollowsPythagoras) {
  const geometry::SurfaceMesh mesh = TiltedPlane();
  const SurfaceQuery surface(mesh);
  const Eigen::Vector2d a(-20.0, -10.0), b(25.0, 15.0);
  const double dz = 0.3 * 45.0 - 0.2 * 25.0;
  EXPECT_NEAR(StraightDistance(surface, a, b).value, std::sqrt(45.0 * 45.0 + 25.0 * 25.0 + dz * dz),
              kSlopedHeightTolerance);
}

TEST(MeasuresTest, AreaOfARegionOnATiltedPlaneIsItsProjectionOverCosine) {
  const geometry::SurfaceMesh mesh = TiltedPlane();
  const SurfaceQuery surface(mesh);
  // A non-convex L-shaped region, 700 mm^2 in x-y, edges off the grid.
  const Polygon2d region = {{-10.3, -10.1}, {19.7, -10.1}, {19.7, 9.9},
                            {9.7, 9.9},     {9.7, 0.0},    {-10.3, 0.0}};
  const double xy_area = 30.0 * 10.1 + 10.0 * 9.9;
  const double stretch = std::sqrt(1.0 + 0.3 * 0.3 + 0.2 * 0.2);
  EXPECT_NEAR(SurfaceArea(surface, region).value, xy_area * stretch, 1e-6);
}

TEST(MeasuresTest, AreaUncertaintyGrowsWithVertexNoise) {
  const geometry::SurfaceMesh quiet = TiltedPlane(0.0);
  const geometry::SurfaceMesh noisy = TiltedPlane(0.2);
  const Polygon2d region = Square(0.0, 0.0, 20.0);
  EXPECT_EQ(SurfaceArea(SurfaceQuery(quiet), region).uncertainty, 0.0);
  EXPECT_GT(SurfaceArea(SurfaceQuery(noisy), region).uncertainty, 0.0);
}

TEST(MeasuresTest, FacesAreaSumsTheTriangles) {
  const geometry::SurfaceMesh mesh = TiltedPlane();
  const double stretch = std::sqrt(1.0 + 0.3 * 0.3 + 0.2 * 0.2);
  // Faces 0 and 1 are the two halves of the first 2 x 2 mm grid cell.
  EXPECT_NEAR(FacesArea(mesh, {0, 1}).value, 4.0 * stretch, kExactTolerance);
  EXPECT_THROW(FacesArea(mesh, {static_cast<int>(mesh.faces.size())}), MeasurementError);
  EXPECT_THROW(FacesArea(mesh, {}), MeasurementError);
}

// A vertex thrown far away (a damaged file) leaves the rest of the surface
// indexed at its own resolution: every query answers as a scan of all faces
// would, and a small box meets only the faces near it and the stretched ones.
TEST(SurfaceQueryTest, AVertexThrownFarAwayLeavesTheRestAnsweredExactly) {
  geometry::SurfaceMesh mesh = TiltedPlane();
  const int far = static_cast<int>(mesh.positions.size() / 2);
  mesh.positions[far] = Eigen::Vector3d(1e8, -3e7, 5.0);
  const SurfaceQuery query(mesh);
  int stretched = 0;
  for (const Eigen::Vector3i& f : mesh.faces) stretched += (f.array() == far).any() ? 1 : 0;
  ASSERT_GT(stretched, 0);
  for (double x = -39.5; x < 40.0; x += 3.7)
    for (double y = -39.5; y < 40.0; y += 4.1) {
      const Eigen::AlignedBox2d box(Eigen::Vector2d(x, y), Eigen::Vector2d(x + 0.5, y + 0.5));
      std::vector<int> expected;
      for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        Eigen::AlignedBox2d face_box;
        for (int k = 0; k < 3; ++k) face_box.extend(mesh.positions[mesh.faces[f][k]].head<2>());
        if (face_box.intersects(box)) expected.push_back(static_cast<int>(f));
      }
      EXPECT_EQ(query.FacesIn(box), expected) << x << ", " << y;
      EXPECT_LE(query.FacesIn(box).size(), 8u + stretched) << x << ", " << y;
    }
  // A box covering everything finds every face once.
  const Eigen::AlignedBox2d all(Eigen::Vector2d(-1e9, -1e9), Eigen::Vector2d(1e9, 1e9));
  EXPECT_EQ(query.FacesIn(all).size(), mesh.faces.size());
  // Off the plane's own area and away from the stretched faces: nothing.
  EXPECT_FALSE(query.Above(Eigen::Vector2d(-500.0, 500.0)).has_value());
}

TEST(MeasuresTest, ErrorsNameTheInput) {
  geometry::SurfaceMesh cloud = TiltedPlane();
  cloud.faces.clear();
  try {
    const SurfaceQuery surface(cloud);
    FAIL() << "a point cloud was accepted";
  } catch (const MeasurementError& e) {
    EXPECT_NE(std::string(e.what()).find("no faces"), std::string::npos) << e.what();
  }
  const geometry::SurfaceMesh mesh = TiltedPlane();
  const SurfaceQuery surface(mesh);
  try {
    HeightAboveBase(surface, {100.0, 0.0});
    FAIL() << "a point outside the surface was accepted";
  } catch (const MeasurementError& e) {
    EXPECT_NE(std::string(e.what()).find("outside the surface"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SurfaceArea(surface, Square(200.0, 0.0, 5.0)), MeasurementError);
  EXPECT_THROW(SurfaceArea(surface, {{0.0, 0.0}, {1.0, 1.0}}), MeasurementError);
  EXPECT_THROW(FitReferencePlane(surface, Square(200.0, 0.0, 5.0)), MeasurementError);
}

TEST(ReportTest, TableAndJsonCarryEveryRow) {
  const std::vector<ReportRow> rows = {{"lump height", {13.25, 0.2}, "mm"},
                                       {"lump area", {1474.0, 30.0}, "mm^2"}};
  const std::string table = FormatTable(rows);
  EXPECT_NE(table.find("lump height"), std::string::npos);
  EXPECT_NE(table.find("13.25"), std::string::npos);
  EXPECT_NE(table.find("mm^2"), std::string::npos);
  const nlohmann::json json = ToJson(rows);
  ASSERT_EQ(json.size(), 2u);
  EXPECT_EQ(json[1]["name"], "lump area");
  EXPECT_DOUBLE_EQ(json[0]["uncertainty"].get<double>(), 0.2);
}

}  // namespace
}  // namespace bsls::measurement
