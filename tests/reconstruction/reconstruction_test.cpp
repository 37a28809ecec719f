// Reconstruct (thesis 5.2): errors, bridging, smoothing and junctions, on
// decodes made exact from the simulator's ground truth (no rendering).
#include "bsls/reconstruction/calibrated_model.h"
#include "bsls/reconstruction/reconstruction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bsls/simulator/ground_truth.h"
#include "bsls/simulator/scene.h"

namespace bsls::reconstruction {
namespace {

using pattern::Side;

constexpr double kExactMm = 1e-3;  // the truth lines are exact to ~1e-4 px (their root finding)
// A bridged vertex on a plane: the spline's interpolation error over a few
// rows of a nearly straight stripe, mapped to depth (~0.8 mm/px here).
constexpr double kBridgedMm = 0.02;

struct PlaneCase {
  simulator::Scene scene;
  simulator::GroundTruth truth;
};

const PlaneCase& PlaneSetup(Side side) {
  static std::map<Side, PlaneCase> cache;
  auto it = cache.find(side);
  if (it == cache.end()) {
    simulator::Scene scene = simulator::ThesisScene(side, simulator::SurfaceKind::kPlane);
    simulator::GroundTruth truth = simulator::ComputeGroundTruth(scene);
    it = cache.emplace(side, PlaneCase{scene, truth}).first;
  }
  return it->second;
}

TriangulationModel TrueModel(const simulator::Scene& scene) {
  return ModelOfKnownDevices(scene.side, scene.camera, scene.projector);
}

// The ground truth as a perfect decode: every line point, every visible junction.
decoder::DecodeResult ExactDecode(const PlaneCase& setup, bool q_absolute) {
  decoder::DecodeResult r;
  r.ok = true;
  r.side = setup.truth.side;
  r.width = setup.truth.width;
  r.height = setup.truth.height;
  r.q_absolute = q_absolute;
  for (const simulator::TruthLine& line : setup.truth.lines) {
    decoder::DecodedLine out{line.p, {}};
    for (const Eigen::Vector2d& p : line.points) out.points.emplace_back(p.x(), p.y());
    r.lines.push_back(out);
  }
  for (const simulator::TruthJunction& j : setup.truth.junctions)
    if (j.visible)
      r.junctions.push_back(
          {cv::Point2d(j.image.x(), j.image.y()), j.p, q_absolute ? j.v : j.v + 2, j.kind, false});
  return r;
}

class PlaneBothSides : public ::testing::TestWithParam<Side> {};

// A perfect decode of the base plane reconstructs it exactly.
TEST_P(PlaneBothSides, ExactDecodeGivesTheBasePlane) {
  const PlaneCase& setup = PlaneSetup(GetParam());
  ReconstructionReport report;
  const geometry::SurfaceMesh mesh =
      Reconstruct(ExactDecode(setup, true), TrueModel(setup.scene), {}, &report);
  std::string why;
  ASSERT_TRUE(mesh.IsValid(&why)) << why;
  EXPECT_GT(report.measured_samples, 5000);
  EXPECT_EQ(report.dropped_samples, 0);
  EXPECT_GT(report.triangles, 1.5 * report.measured_samples);
  EXPECT_EQ(report.dropped_triangles, 0);
  EXPECT_EQ(report.junctions, report.junctions_by_projector);
  EXPECT_GT(report.junctions, 300);
  int junction_vertices = 0;
  for (std::size_t v = 0; v < mesh.VertexCount(); ++v) {
    EXPECT_NEAR(mesh.positions[v].z(), 0.0, kExactMm);
    EXPECT_GT(mesh.normals[v].z(), 0.999);
    EXPECT_GT(mesh.uncertainty_mm[v], 0.0f);
    junction_vertices += (mesh.flags[v] & geometry::kVertexJunction) != 0;
  }
  EXPECT_EQ(junction_vertices, report.junctions);
  EXPECT_EQ(report.vertices, static_cast<int>(mesh.VertexCount()));
}

INSTANTIATE_TEST_SUITE_P(Sides, PlaneBothSides, ::testing::Values(Side::kLeft, Side::kRight),
                         [](const auto& test_info) {
                           return std::string(pattern::ToString(test_info.param));
                         });

// Short gaps are bridged on the plane (flagged, less certain); long ones stay holes.
TEST(Reconstruct, BridgesShortGapsOnly) {
  const PlaneCase& setup = PlaneSetup(Side::kLeft);
  decoder::DecodeResult decode = ExactDecode(setup, false);
  decoder::DecodedLine& line = decode.lines[3];
  ASSERT_GT(line.points.size(), 200u);
  const int p = line.p;
  // A 4-row gap at index 60 and a 30-row gap at index 150.
  line.points.erase(line.points.begin() + 150, line.points.begin() + 180);
  line.points.erase(line.points.begin() + 60, line.points.begin() + 64);
  ReconstructionParams params;
  params.max_bridge_rows = 6;
  params.include_junctions = false;
  ReconstructionReport report;
  const geometry::SurfaceMesh mesh = Reconstruct(decode, TrueModel(setup.scene), params, &report);
  EXPECT_EQ(report.bridged_samples, 4);
  float measured_sigma = 0.0f, bridged_sigma = 0.0f;
  for (std::size_t v = 0; v < mesh.VertexCount(); ++v) {
    if (mesh.line[v] != p) continue;
    if (mesh.flags[v] & geometry::kVertexBridged) {
      EXPECT_NEAR(mesh.positions[v].z(), 0.0, kBridgedMm);
      bridged_sigma = mesh.uncertainty_mm[v];
    } else {
      measured_sigma = mesh.uncertainty_mm[v];
    }
  }
  EXPECT_GT(bridged_sigma, 2.0f * measured_sigma);
  params.max_bridge_rows = 0;
  Reconstruct(decode, TrueModel(setup.scene), params, &report);
  EXPECT_EQ(report.bridged_samples, 0);
}

// Thesis eq. 5.32 reduces the scatter of noisy centres and flags what it moved.
TEST(Reconstruct, SmoothingReducesNoiseAndFlags) {
  const PlaneCase& setup = PlaneSetup(Side::kLeft);
  decoder::DecodeResult decode = ExactDecode(setup, false);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.2);
  for (decoder::DecodedLine& line : decode.lines)
    for (cv::Point2d& point : line.points) point.x += noise(rng);
  const auto rms_z = [](const geometry::SurfaceMesh& mesh, int* smoothed) {
    double sum = 0.0;
    *smoothed = 0;
    for (std::size_t v = 0; v < mesh.VertexCount(); ++v) {
      sum += mesh.positions[v].z() * mesh.positions[v].z();
      *smoothed += (mesh.flags[v] & geometry::kVertexSmoothed) != 0;
    }
    return std::sqrt(sum / mesh.VertexCount());
  };
  ReconstructionParams params;
  params.include_junctions = false;
  int smoothed = 0;
  const double raw = rms_z(Reconstruct(decode, TrueModel(setup.scene), params), &smoothed);
  EXPECT_EQ(smoothed, 0);
  params.smooth_lines = true;
  ReconstructionReport report;
  const double filtered =
      rms_z(Reconstruct(decode, TrueModel(setup.scene), params, &report), &smoothed);
  EXPECT_EQ(smoothed, report.smoothed_samples);
  EXPECT_GT(smoothed, 5000);
  // Independent noise: sigma falls to sqrt(38) / 8 = 0.77 of the raw one.
  EXPECT_NEAR(filtered / raw, 0.77, 0.05) << "raw " << raw << " mm, smoothed " << filtered;
}

TEST(Reconstruct, FailsClearlyWithoutLabelledLines) {
  const PlaneCase& setup = PlaneSetup(Side::kLeft);
  decoder::DecodeResult decode;
  decode.ok = true;
  decode.side = Side::kLeft;
  try {
    Reconstruct(decode, TrueModel(setup.scene));
    FAIL() << "no error";
  } catch (const ReconstructionError& e) {
    EXPECT_NE(std::string(e.what()).find("no labelled line"), std::string::npos) << e.what();
  }
  decode.ok = false;
  decode.error = "blank frame";
  try {
    Reconstruct(decode, TrueModel(setup.scene));
    FAIL() << "no error";
  } catch (const ReconstructionError& e) {
    EXPECT_NE(std::string(e.what()).find("blank frame"), std::string::npos) << e.what();
  }
  decoder::DecodeResult right = ExactDecode(PlaneSetup(Side::kRight), false);
  EXPECT_THROW(Reconstruct(right, TrueModel(setup.scene)), ReconstructionError);
  // Lines the calibration does not know: nothing meets a plane.
  TriangulationModel model = TrueModel(setup.scene);
  std::get<CalibratedGeometry>(model.geometry).light_plane = [](int) {
    return std::optional<calibration::LightPlane>();
  };
  EXPECT_THROW(Reconstruct(ExactDecode(setup, false), model), ReconstructionError);
}

}  // namespace
}  // namespace bsls::reconstruction
