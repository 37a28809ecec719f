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

// The cubic Hermite curve from (y0, x0) with slope m0 to (y1, x1) with slope
// m1 (dx/drow), at row y.
double Hermite(double y0, double x0, double m0, double y1, double x1, double m1, double y) {
  const double h = y1 - y0, t = (y - y0) / h, t2 = t * t, t3 = t2 * t;
  return (2 * t3 - 3 * t2 + 1) * x0 + (t3 - 2 * t2 + t) * h * m0 + (-2 * t3 + 3 * t2) * x1 +
         (t3 - t2) * h * m1;
}

// The slope dx/drow of a line's centres at `row`, from the measured rows
// within 3 on the side `step` (-1 above, +1 below) by least squares; the
// chord slope `fallback` when fewer than two.
double EndSlope(const std::map<int, double>& x_of_row, int row, int step, double fallback) {
  double n = 0, sy = 0, sx = 0, syy = 0, syx = 0;
  for (int k = 0; k <= 3; ++k) {
    const auto it = x_of_row.find(row + step * k);
    if (it == x_of_row.end()) continue;
    const double y = step * k;
    n += 1;
    sy += y;
    sx += it->second;
    syy += y * y;
    syx += y * it->second;
  }
  const double den = n * syy - sy * sy;
  if (n < 2 || std::abs(den) < 1e-9) return fallback;
  return (n * syx - sy * sx) / den;
}

// Thesis Appendix B extended: the centres x(row) across a gap (row0, row1)
// that holds junctions of the line, pinned at them: anchors are the gap's
// ends and the junctions (sorted by row), each stretch between two a cubic
// Hermite curve, slopes at the ends from the measured rows beyond them,
// Catmull-Rom slopes at the junctions. Empty when a junction lies more than
// `max_offset` px from the curve across the gap without it.
std::vector<double> AnchoredBridge(const std::map<int, double>& x_of_row, int row0, int row1,
                                   const std::vector<cv::Point2d>& junctions, double max_offset) {
  const double x0 = x_of_row.at(row0), x1 = x_of_row.at(row1);
  const double chord = (x1 - x0) / (row1 - row0);
  const double m0 = EndSlope(x_of_row, row0, -1, chord), m1 = EndSlope(x_of_row, row1, +1, chord);
  std::vector<cv::Point2d> anchors{{x0, double(row0)}};
  for (const cv::Point2d& j : junctions) {  // sorted by row, inside (row0 + 0.5, row1 - 0.5)
    const double across = Hermite(row0, x0, m0, row1, x1, m1, j.y);
    if (std::abs(across - j.x) > max_offset) return {};
    if (j.y - anchors.back().y >= 0.5) anchors.push_back(j);  // one anchor per row: no h = 0
  }
  anchors.push_back({x1, double(row1)});
  std::vector<double> slopes(anchors.size());
  slopes.front() = m0;
  slopes.back() = m1;
  for (std::size_t k = 1; k + 1 < anchors.size(); ++k)
    slopes[k] = (anchors[k + 1].x - anchors[k - 1].x) / (anchors[k + 1].y - anchors[k - 1].y);
  std::vector<double> xs;
  std::size_t k = 0;
  for (int row = row0 + 1; row < row1; ++row) {
    while (k + 2 < anchors.size() && anchors[k + 1].y <= row) ++k;
    xs.push_back(Hermite(anchors[k].y, anchors[k].x, slopes[k], anchors[k + 1].y, anchors[k + 1].x,
                         slopes[k + 1], row));
  }
  return xs;
}

// Throws unless the params are valid and the decode succeeded, is of the
// triangulator's side and has at least one labelled line sample.
void CheckInputs(const decoder::DecodeResult& decode, const Triangulator& triangulator,
                 const ReconstructionParams& params) {
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
}

// A line's centres that met its light plane: their vertices, and the image
// column of each, by index and by row.
struct MeasuredLine {
  std::vector<LineVertex> vertices;
  std::vector<double> x;
  std::map<int, double> x_of_row;
};

// Measured samples: each centre of line p triangulated; those missing the
// plane counted in r.dropped_samples.
MeasuredLine TriangulateCentres(int p, const std::vector<Centre>& centres,
                                const Triangulator& triangulator, ReconstructionReport& r) {
  MeasuredLine m;
  for (const Centre& c : centres) {
    const auto point = triangulator.LineSample(p, {c.x, double(c.row)}, c.sigma_px);
    if (!point) {
      ++r.dropped_samples;
      continue;
    }
    m.vertices.push_back({c.row, point->position, float(point->sigma_mm), c.flags});
    m.x.push_back(c.x);
    m.x_of_row[c.row] = c.x;
  }
  return m;
}

// Thesis Appendix B: the image columns x(row) of the rows missing between
// measured vertices i and i + 1 of line p, by a cubic B-spline through the
// centres x(row) at uniform knots: the gap's two ends and, where the line
// has them, one more knot a gap-length beyond each end; pinned at the line's
// junctions (AnchoredBridge) for a gap too long for the spline alone. Empty
// when the gap is not bridged. `step` is the line's median step (mm).
std::vector<double> GapColumns(const MeasuredLine& m, std::size_t i, int p,
                               const std::multimap<int, cv::Point2d>& junctions_of,
                               const ReconstructionParams& params, double step) {
  const std::vector<LineVertex>& measured = m.vertices;
  const MeshParams& mesh_params = params.mesh;
  const int row0 = measured[i].row, row1 = measured[i + 1].row;
  const int missing = row1 - row0 - 1;
  if (missing < 1) return {};
  // The line's junctions inside the gap, clear of its ends.
  std::vector<cv::Point2d> inside;
  if (missing > params.max_bridge_rows) {
    if (missing > params.max_anchored_bridge_rows) return {};
    const auto [from, to] = junctions_of.equal_range(p);
    for (auto it = from; it != to; ++it)
      if (it->second.y > row0 + 0.5 && it->second.y < row1 - 0.5) inside.push_back(it->second);
    if (inside.empty()) return {};
    std::sort(inside.begin(), inside.end(),
              [](const cv::Point2d& a, const cv::Point2d& b) { return a.y < b.y; });
  }
  const int h = missing + 1;  // knot spacing, rows
  // A jump in depth across the gap is an occlusion, not a break: no bridge.
  const double jump = (measured[i + 1].position - measured[i].position).norm();
  if (jump > std::max(mesh_params.min_along_jump_mm, mesh_params.max_along_ratio * step * h))
    return {};
  if (!inside.empty())
    return AnchoredBridge(m.x_of_row, row0, row1, inside, params.max_anchor_offset_px);
  std::vector<double> knots;
  int first_knot_row = row0;
  if (const auto it = m.x_of_row.find(row0 - h); it != m.x_of_row.end()) {
    knots.push_back(it->second);
    first_knot_row = row0 - h;
  }
  knots.push_back(m.x[i]);
  knots.push_back(m.x[i + 1]);
  if (const auto it = m.x_of_row.find(row1 + h); it != m.x_of_row.end())
    knots.push_back(it->second);
  const std::optional<CubicBSpline> spline = CubicBSpline::Interpolate(knots);
  if (!spline) return {};
  std::vector<double> xs;
  for (int row = row0 + 1; row < row1; ++row)
    xs.push_back((*spline)(double(row - first_knot_row) / h));
  return xs;
}

// Line p's measured vertices with the bridged ones of each short gap
// between them, in row order; bridged samples counted in r.
std::vector<LineVertex> BridgeGaps(int p, const MeasuredLine& m,
                                   const std::multimap<int, cv::Point2d>& junctions_of,
                                   const Triangulator& triangulator,
                                   const ReconstructionParams& params, ReconstructionReport& r) {
  const std::vector<LineVertex>& measured = m.vertices;
  const UncertaintyParams& u = triangulator.model().uncertainty;
  std::vector<double> steps;
  for (std::size_t i = 0; i + 1 < measured.size(); ++i)
    if (measured[i + 1].row == measured[i].row + 1)
      steps.push_back((measured[i + 1].position - measured[i].position).norm());
  const double step = Median(steps);
  std::vector<LineVertex> vertices;
  for (std::size_t i = 0; i < measured.size(); ++i) {
    vertices.push_back(measured[i]);
    if (i + 1 == measured.size()) break;
    const std::vector<double> xs = GapColumns(m, i, p, junctions_of, params, step);
    if (xs.empty()) continue;
    const int row0 = measured[i].row, row1 = measured[i + 1].row;
    const double sigma = std::hypot(u.stripe_centre_sigma_px, params.bridge_sigma_px);
    for (int row = row0 + 1; row < row1; ++row) {
      const double x = xs[static_cast<size_t>(row - row0 - 1)];
      const auto point = triangulator.LineSample(p, {x, double(row)}, sigma);
      if (!point) continue;
      vertices.push_back({row, point->position, float(point->sigma_mm), geometry::kVertexBridged});
      ++r.bridged_samples;
    }
  }
  return vertices;
}

// Appends `vertices` to line p of `by_p`. A line listed twice by the
// decoder: its samples merge, first kept per row.
void MergeLine(int p, const std::vector<LineVertex>& vertices,
               std::map<int, TriangulatedLine>& by_p) {
  TriangulatedLine& out = by_p[p];
  out.p = p;
  out.vertices.insert(out.vertices.end(), vertices.begin(), vertices.end());
  std::stable_sort(out.vertices.begin(), out.vertices.end(),
                   [](const LineVertex& a, const LineVertex& b) { return a.row < b.row; });
  out.vertices.erase(std::unique(out.vertices.begin(), out.vertices.end(),
                                 [](const auto& a, const auto& b) { return a.row == b.row; }),
                     out.vertices.end());
}

// Appends a vertex for every decoded junction seen (not interpolated) that
// triangulates, its normal from the line vertex on its row (else towards
// the camera); counted in r.
void AddJunctions(const decoder::DecodeResult& decode, const Triangulator& triangulator,
                  const std::vector<TriangulatedLine>& lines, geometry::SurfaceMesh& mesh,
                  ReconstructionReport& r) {
  // Vertex of (p, row) for the junctions' normals.
  std::map<std::pair<int, int>, int> vertex_of;
  int index = 0;
  for (const TriangulatedLine& line : lines)
    for (const LineVertex& v : line.vertices) vertex_of[{line.p, v.row}] = index++;
  for (const decoder::DecodedJunction& j : decode.junctions) {
    // Placed from its line's junctions (thesis 5.1.4.6), not seen: its row
    // is no measurement, and its line's centres carry the surface there.
    if (j.interpolated) continue;
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

}  // namespace

bool ReconstructionParams::IsValid(std::string* error) const {
  if (!mesh.IsValid(error)) return false;
  if (max_bridge_rows < 0 || max_bridge_rows > 64)
    return Fail(error, "reconstruction: max_bridge_rows must be in [0, 64]");
  if (max_anchored_bridge_rows < 0 || max_anchored_bridge_rows > 64)
    return Fail(error, "reconstruction: max_anchored_bridge_rows must be in [0, 64]");
  if (!std::isfinite(max_anchor_offset_px) || max_anchor_offset_px <= 0.0)
    return Fail(error, "reconstruction: max_anchor_offset_px must be finite and > 0");
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
  CheckInputs(decode, triangulator, params);

  ReconstructionReport r;
  const UncertaintyParams& u = triangulator.model().uncertainty;
  const MeshParams& mesh_params = params.mesh;
  std::map<int, TriangulatedLine> by_p;          // ordered by p
  std::multimap<int, cv::Point2d> junctions_of;  // p -> image position
  for (const decoder::DecodedJunction& j : decode.junctions)
    if (std::isfinite(j.position.x) && std::isfinite(j.position.y))
      junctions_of.emplace(j.p, j.position);
  for (const decoder::DecodedLine& line : decode.lines) {
    std::vector<Centre> centres = CentresOf(line, u.stripe_centre_sigma_px);
    if (centres.empty()) continue;
    if (params.smooth_lines) r.smoothed_samples += SmoothCentres(&centres);
    const MeasuredLine measured = TriangulateCentres(line.p, centres, triangulator, r);
    r.measured_samples += static_cast<int>(measured.vertices.size());
    if (measured.vertices.empty()) continue;
    MergeLine(line.p, BridgeGaps(line.p, measured, junctions_of, triangulator, params, r), by_p);
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
  if (params.include_junctions) AddJunctions(decode, triangulator, lines, mesh, r);

  r.vertices = static_cast<int>(mesh.VertexCount());
  r.triangles = mesh_report.triangles;
  r.dropped_triangles = mesh_report.dropped_across + 2 * mesh_report.dropped_along;
  r.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (report) *report = r;
  return mesh;
}

}  // namespace bsls::reconstruction
