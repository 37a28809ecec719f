#include "bsls/reconstruction/reconstruction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>

#include "bsls/reconstruction/bspline.h"

namespace bsls::reconstruction {
namespace {

// Thesis eq. 5.32 weights (1, 6, 1) / 8: for independent centre errors the
// smoothed centre's sigma is sqrt(1 + 36 + 1) / 8 of the raw one.
constexpr double kSmoothedSigmaScale = 0.770552;  // sqrt(38) / 8

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

// One stripe centre of a line on its way to the mesh.
struct Centre {
  int row = 0;
  double x = 0.0;  // image column, px
  double sigma_px = 0.0;
  std::uint8_t flags = 0;
};

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The decoder's centres of one line, one per row (the first of a repeated row).
std::vector<Centre> CentresOf(const decoder::DecodedLine& line, double sigma_px) {
  std::vector<Centre> centres;
  centres.reserve(line.points.size());
  for (const cv::Point2d& point : line.points) {
    if (!std::isfinite(point.x) || !std::isfinite(point.y)) continue;
    centres.push_back({static_cast<int>(std::lround(point.y)), point.x, sigma_px, 0});
  }
  std::stable_sort(centres.begin(), centres.end(),
                   [](const Centre& a, const Centre& b) { return a.row < b.row; });
  centres.erase(std::unique(centres.begin(), centres.end(),
                            [](const Centre& a, const Centre& b) { return a.row == b.row; }),
                centres.end());
  return centres;
}

// Thesis eq. 5.32 along every run of consecutive rows; returns how many moved.
int SmoothCentres(std::vector<Centre>* centres) {
  std::vector<Centre>& c = *centres;
  std::vector<double> smoothed(c.size());
  int moved = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    smoothed[i] = c[i].x;
    if (i == 0 || i + 1 == c.size()) continue;
    if (c[i - 1].row + 1 != c[i].row || c[i].row + 1 != c[i + 1].row) continue;
    smoothed[i] = (c[i - 1].x + 6.0 * c[i].x + c[i + 1].x) / 8.0;
    c[i].flags |= geometry::kVertexSmoothed;
    c[i].sigma_px *= kSmoothedSigmaScale;
    ++moved;
  }
  for (std::size_t i = 0; i < c.size(); ++i) c[i].x = smoothed[i];
  return moved;
}

}  // namespace

bool ReconstructionParams::IsValid(std::string* error) const {
  if (!mesh.IsValid(error)) return false;
  if (max_bridge_rows < 0 || max_bridge_rows > 64)
    return Fail(error, "reconstruction: max_bridge_rows must be in [0, 64]");
  if (!std::isfinite(bridge_sigma_px) || bridge_sigma_px < 0.0)
    return Fail(error, "reconstruction: bridge_sigma_px must be finite and >= 0");
  return true;
}

geometry::SurfaceMesh Reconstruct(const decoder::DecodeResult& decode,
                                  const TriangulationModel& model,
                                  const ReconstructionParams& params,
                                  ReconstructionReport* report) {
  return Reconstruct(decode, Triangulator(model), params, report);
}

geometry::SurfaceMesh Reconstruct(const decoder::DecodeResult& decode,
                                  const Triangulator& triangulator,
                                  const ReconstructionParams& params,
                                  ReconstructionReport* report) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!params.IsValid(&why)) throw std::invalid_argument(why);
  if (!decode.ok) throw ReconstructionError("reconstruction: the decode failed: " + decode.error);
  const pattern::Side side = triangulator.model().side;
  if (decode.side != side)
    throw ReconstructionError("reconstruction: the decode is of the " +
                              std::string(pattern::ToString(decode.side)) +
                              " side, the model of the " + std::string(pattern::ToString(side)));
  const bool any_sample = std::any_of(decode.lines.begin(), decode.lines.end(),
                                      [](const auto& l) { return !l.points.empty(); });
  if (!any_sample)
    throw ReconstructionError("reconstruction: the decode has no labelled line samples");

  ReconstructionReport r;
  const UncertaintyParams& u = triangulator.model().uncertainty;
  const MeshParams& mesh_params = params.mesh;
  std::map<int, TriangulatedLine> by_p;  // ordered by p
  for (const decoder::DecodedLine& line : decode.lines) {
    std::vector<Centre> centres = CentresOf(line, u.stripe_centre_sigma_px);
    if (centres.empty()) continue;
    if (params.smooth_lines) r.smoothed_samples += SmoothCentres(&centres);

    // Measured samples.
    std::vector<LineVertex> measured;
    std::vector<double> measured_x;
    std::map<int, double> x_of_row;
    for (const Centre& c : centres) {
      const auto point = triangulator.LineSample(line.p, {c.x, double(c.row)}, c.sigma_px);
      if (!point) {
        ++r.dropped_samples;
        continue;
      }
      measured.push_back({c.row, point->position, float(point->sigma_mm), c.flags});
      measured_x.push_back(c.x);
      x_of_row[c.row] = c.x;
    }
    r.measured_samples += static_cast<int>(measured.size());
    if (measured.empty()) continue;

    // Thesis Appendix B: bridge short gaps by a cubic B-spline through the
    // centres x(row) at uniform knots: the gap's two ends and, where the line
    // has them, one more knot a gap-length beyond each end.
    std::vector<double> steps;
    for (std::size_t i = 0; i + 1 < measured.size(); ++i)
      if (measured[i + 1].row == measured[i].row + 1)
        steps.push_back((measured[i + 1].position - measured[i].position).norm());
    const double step = Median(steps);
    std::vector<LineVertex> vertices;
    for (std::size_t i = 0; i < measured.size(); ++i) {
      vertices.push_back(measured[i]);
      if (i + 1 == measured.size()) break;
      const int row0 = measured[i].row, row1 = measured[i + 1].row;
      const int missing = row1 - row0 - 1;
      if (missing < 1 || missing > params.max_bridge_rows) continue;
      const int h = missing + 1;  // knot spacing, rows
      // A jump in depth across the gap is an occlusion, not a break: no bridge.
      const double jump = (measured[i + 1].position - measured[i].position).norm();
      if (jump > std::max(mesh_params.min_along_jump_mm, mesh_params.max_along_ratio * step * h))
        continue;
      std::vector<double> knots;
      int first_knot_row = row0;
      if (const auto it = x_of_row.find(row0 - h); it != x_of_row.end()) {
        knots.push_back(it->second);
        first_knot_row = row0 - h;
      }
      knots.push_back(measured_x[i]);
      knots.push_back(measured_x[i + 1]);
      if (const auto it = x_of_row.find(row1 + h); it != x_of_row.end())
        knots.push_back(it->second);
      const std::optional<CubicBSpline> spline = CubicBSpline::Interpolate(knots);
      if (!spline) continue;
      const double sigma = std::hypot(u.stripe_centre_sigma_px, params.bridge_sigma_px);
      for (int row = row0 + 1; row < row1; ++row) {
        const double x = (*spline)(double(row - first_knot_row) / h);
        const auto point = triangulator.LineSample(line.p, {x, double(row)}, sigma);
        if (!point) continue;
        vertices.push_back(
            {row, point->position, float(point->sigma_mm), geometry::kVertexBridged});
        ++r.bridged_samples;
      }
    }
    TriangulatedLine& out = by_p[line.p];
    out.p = line.p;
    // A line listed twice by the decoder: its samples merge, first kept per row.
    out.vertices.insert(out.vertices.end(), vertices.begin(), vertices.end());
    std::stable_sort(out.vertices.begin(), out.vertices.end(),
                     [](const LineVertex& a, const LineVertex& b) { return a.row < b.row; });
    out.vertices.erase(std::unique(out.vertices.begin(), out.vertices.end(),
                                   [](const auto& a, const auto& b) { return a.row == b.row; }),
                       out.vertices.end());
  }
  if (r.measured_samples == 0)
    throw ReconstructionError("reconstruction: none of the " + std::to_string(r.dropped_samples) +
                              " line samples meets its light plane (lines unknown to the "
                              "calibration, or rays missing the planes)");

  std::vector<TriangulatedLine> lines;
  for (auto& [p, line] : by_p) lines.push_back(std::move(line));
  MeshReport mesh_report;
  geometry::SurfaceMesh mesh =
      BuildSurfaceMesh(lines, triangulator.CameraCentre(), mesh_params, &mesh_report);

  if (params.include_junctions) {
    // Vertex of (p, row) for the junctions' normals.
    std::map<std::pair<int, int>, int> vertex_of;
    int index = 0;
    for (const TriangulatedLine& line : lines)
      for (const LineVertex& v : line.vertices) vertex_of[{line.p, v.row}] = index++;
    for (const decoder::DecodedJunction& j : decode.junctions) {
      const Eigen::Vector2d image(j.position.x, j.position.y);
      if (!image.allFinite()) {
        ++r.dropped_junctions;
        continue;
      }
      const auto point = triangulator.Junction(j.p, j.q, image, decode.q_absolute);
      if (!point) {
        ++r.dropped_junctions;
        continue;
      }
      mesh.positions.push_back(point->position);
      mesh.uncertainty_mm.push_back(float(point->sigma_mm));
      mesh.line.push_back(j.p);
      mesh.flags.push_back(geometry::kVertexJunction);
      const auto near = vertex_of.find({j.p, static_cast<int>(std::lround(image.y()))});
      Eigen::Vector3d normal = (triangulator.CameraCentre() - point->position).normalized();
      if (near != vertex_of.end()) normal = mesh.normals[near->second];
      mesh.normals.push_back(normal);
      ++r.junctions;
      if (triangulator.HasProjector() && decode.q_absolute) ++r.junctions_by_projector;
    }
  }

  r.vertices = static_cast<int>(mesh.VertexCount());
  r.triangles = mesh_report.triangles;
  r.dropped_triangles = mesh_report.dropped_across + 2 * mesh_report.dropped_along;
  r.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (report) *report = r;
  return mesh;
}

}  // namespace bsls::reconstruction
