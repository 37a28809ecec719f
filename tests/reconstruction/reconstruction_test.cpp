// Reconstruct (thesis 5.2): errors, bridging, smoothing and junctions, on
// decodes made exact from the simulator's ground truth (no rendering).
#include "bsls/reconstruction/reconstruction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <random>

#include "bsls/reconstruction/calibrated_model.h"
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

const PlaneCase& SceneSetup(Side side, simulator::SurfaceKind kind) {
  static std::map<std::pair<Side, simulator::SurfaceKind>, PlaneCase> cache;
  auto it = cache.find({side, kind});
  if (it == cache.end()) {
    simulator::Scene scene = simulator::ThesisScene(side, kind);
    simulator::GroundTruth truth = simulator::ComputeGroundTruth(scene);
    it = cache.emplace(std::make_pair(side, kind), PlaneCase{scene, truth}).first;
  }
  return it->second;
}

const PlaneCase& PlaneSetup(Side side) { return SceneSetup(side, simulator::SurfaceKind::kPlane); }

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

// The decoder leaves out the rows beside a steep line's segment (up to 15
// at |dx/dy| 2): gaps longer than max_bridge_rows that hold a junction of
// the line are bridged through it. On the face's exact decode, every
// junction on a stretch steeper than |dx/dy| 0.5 gets such a gap (9 rows
// each side of it); the bridged vertices lie within 0.5 mm of the exact
// ones (0.15 mm RMS; measured 0.41 and 0.10 mm). A junction moved 4 px off its line pins nothing
// (the gap stays a hole), and without junctions the gaps stay holes.
TEST(Reconstruct, GapsAroundJunctionsAreBridgedThroughThem) {
  const PlaneCase& setup = SceneSetup(Side::kLeft, simulator::SurfaceKind::kFace);
  const TriangulationModel model = TrueModel(setup.scene);
  const decoder::DecodeResult exact = ExactDecode(setup, true);
  ReconstructionParams params;
  params.include_junctions = false;
  const geometry::SurfaceMesh truth_mesh = Reconstruct(exact, model, params);
  // (p, row) -> exact vertex.
  std::map<std::pair<int, int>, Eigen::Vector3d> exact_at;
  {
    std::size_t v = 0;
    for (const decoder::DecodedLine& line : exact.lines)
      for (const cv::Point2d& point : line.points)
        if (v < truth_mesh.VertexCount() && truth_mesh.line[v] == line.p)
          exact_at[{line.p, static_cast<int>(std::lround(point.y))}] = truth_mesh.positions[v++];
  }
  ASSERT_EQ(exact_at.size(), truth_mesh.VertexCount());

  constexpr int kHalfGap = 9;
  decoder::DecodeResult gapped = exact;
  std::vector<std::size_t> pinned;  // indices of the junctions that get a gap
  for (std::size_t k = 0; k < gapped.junctions.size(); ++k) {
    const decoder::DecodedJunction& j = gapped.junctions[k];
    auto line = std::find_if(gapped.lines.begin(), gapped.lines.end(),
                             [&](const auto& l) { return l.p == j.p; });
    ASSERT_NE(line, gapped.lines.end());
    // The line's slope over the gap, from the exact points at its ends.
    std::optional<cv::Point2d> above, below;
    for (const cv::Point2d& point : exact.lines[line - gapped.lines.begin()].points) {
      if (std::abs(point.y - (j.position.y - kHalfGap - 1)) < 0.5) above = point;
      if (std::abs(point.y - (j.position.y + kHalfGap + 1)) < 0.5) below = point;
    }
    if (!above || !below || std::abs((below->x - above->x) / (below->y - above->y)) < 0.5) continue;
    const auto before = line->points.size();
    std::erase_if(line->points, [&](const cv::Point2d& point) {
      return std::abs(point.y - j.position.y) <= kHalfGap;
    });
    if (line->points.size() + 2 * kHalfGap - 1 <= before) pinned.push_back(k);
  }
  ASSERT_GE(pinned.size(), 20u);

  ReconstructionReport report;
  const geometry::SurfaceMesh mesh = Reconstruct(gapped, model, params, &report);
  double sum = 0.0, worst = 0.0;
  int bridged = 0;
  for (std::size_t v = 0; v < mesh.VertexCount(); ++v) {
    if (!(mesh.flags[v] & geometry::kVertexBridged)) continue;
    // The bridged vertex's row: the exact vertex of its line nearest to it.
    double best = 1e9;
    for (const auto& [key, position] : exact_at)
      if (key.first == mesh.line[v]) best = std::min(best, (position - mesh.positions[v]).norm());
    sum += best * best;
    worst = std::max(worst, best);
    ++bridged;
  }
  // Junctions closer than a gap on one line merge their gaps beyond
  // max_anchored_bridge_rows: those stay holes.
  EXPECT_GE(bridged, static_cast<int>(pinned.size()) * kHalfGap);
  EXPECT_LT(std::sqrt(sum / bridged), 0.15) << bridged << " bridged";
  EXPECT_LT(worst, 0.5);

  // A junction listed twice (a line decoded twice) pins the gap once.
  decoder::DecodeResult doubled = gapped;
  for (std::size_t k : pinned) doubled.junctions.push_back(gapped.junctions[k]);
  ReconstructionReport doubled_report;
  const geometry::SurfaceMesh doubled_mesh = Reconstruct(doubled, model, params, &doubled_report);
  EXPECT_EQ(doubled_report.bridged_samples, report.bridged_samples);
  for (const Eigen::Vector3d& position : doubled_mesh.positions) ASSERT_TRUE(position.allFinite());

  // A junction moved off its line pins nothing.
  decoder::DecodeResult moved = gapped;
  for (std::size_t k : pinned) moved.junctions[k].position.x += 4.0;
  ReconstructionReport moved_report;
  Reconstruct(moved, model, params, &moved_report);
  EXPECT_LT(moved_report.bridged_samples, report.bridged_samples / 5);
  // Without junctions, gaps longer than max_bridge_rows stay holes.
  decoder::DecodeResult bare = gapped;
  bare.junctions.clear();
  ReconstructionReport bare_report;
  Reconstruct(bare, model, params, &bare_report);
  EXPECT_LT(bare_report.bridged_samples, report.bridged_samples / 5);
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
