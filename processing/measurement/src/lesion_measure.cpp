#include "bsls/measurement/lesion_measure.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "hole_fill.h"
#include "polygon.h"
#include "stripe_field.h"

namespace bsls::measurement {
namespace {

// MAD to Gaussian sigma.
constexpr double kMadToSigma = 1.4826;
// Robust sigma floor (mm): keeps Huber weights finite on exact data.
constexpr double kMinRobustSigmaMm = 1e-6;
// Quadratic terms of the peak window fit, and their count.
constexpr int kQuadricTerms = 6;
constexpr int kPlaneTerms = 3;
constexpr int kCubicTerms = 10;
// The level cut's lattice (mm; 0.5 mm moved the thesis lesions' areas by
// under 0.05 % and took twice as long) on faces whose deviations come within
// this fraction of the level of it, at most this many steps per edge; and
// how far past the region (mm) the stripes that steer the cubic are taken.
constexpr double kSubdivisionMm = 1.0;
constexpr double kSubdivisionMargin = 0.5;
constexpr int kMaxSubdivisions = 64;
constexpr double kFieldMarginMm = 15.0;
// The lesion's top: vertices within this fraction of the extreme deviation.
constexpr double kTopFraction = 0.9;
// A peak window whose minor/major scatter is below this holds one stripe.
constexpr double kCollinearRatio = 0.05;
// The grid the region's holes are filled on: cell side, and how far it
// reaches past the region so that surface around a hole on the region's
// boundary encloses it.
constexpr double kFillCellMm = 0.5;
constexpr double kFillMarginMm = 4.0;
// A larger region gets larger cells: at most this many, which bounds the
// fill's memory and time (a 100 mm square at 0.5 mm; a region of 80 mm
// radius with a quarter of it to fill took 0.6 s here at 113 000 cells).
constexpr double kMaxFillCells = 40000.0;
// Regions wider than this (mm) are no lesion's: no fill.
constexpr double kMaxFillExtentMm = 2000.0;

int TermsOf(ReferenceKind kind) {
  switch (kind) {
    case ReferenceKind::kPlane:
      return kPlaneTerms;
    case ReferenceKind::kQuadric:
      return kQuadricTerms;
    case ReferenceKind::kCubic:
      return kCubicTerms;
    case ReferenceKind::kBaseline:
      return 0;
  }
  return kQuadricTerms;
}

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

// Monomials 1, x, y [, x^2, xy, y^2] at offset d.
Eigen::VectorXd Basis(const Eigen::Vector2d& d, int terms) {
  Eigen::VectorXd phi(terms);
  phi[0] = 1.0;
  phi[1] = d.x();
  phi[2] = d.y();
  if (terms >= kQuadricTerms) {
    phi[3] = d.x() * d.x();
    phi[4] = d.x() * d.y();
    phi[5] = d.y() * d.y();
  }
  if (terms >= kCubicTerms) {
    phi[6] = d.x() * d.x() * d.x();
    phi[7] = d.x() * d.x() * d.y();
    phi[8] = d.x() * d.y() * d.y();
    phi[9] = d.y() * d.y() * d.y();
  }
  return phi;
}

double Median(std::vector<double> values) {
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The vertices of the faces meeting the region's bounding box.
std::vector<int> CandidateVertices(const SurfaceQuery& surface, const Eigen::AlignedBox2d& box) {
  std::vector<int> vertices;
  for (int f : surface.FacesIn(box))
    for (int k = 0; k < 3; ++k) vertices.push_back(surface.mesh().faces[f][k]);
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  return vertices;
}

// The vertices of `surface` outside `region` within `width_mm` of its boundary.
std::vector<int> RingVertices(const SurfaceQuery& surface, const Polygon2d& region,
                              double width_mm) {
  std::vector<int> vertices;
  for (int v : CandidateVertices(surface, internal::Grown(internal::Bounds(region), width_mm))) {
    const Eigen::Vector2d xy = surface.mesh().positions[v].head<2>();
    if (!internal::Contains(region, xy) && internal::DistanceToBoundary(region, xy) <= width_mm)
      vertices.push_back(v);
  }
  return vertices;
}

}  // namespace

std::string ToString(ReferenceKind kind) {
  switch (kind) {
    case ReferenceKind::kPlane:
      return "plane";
    case ReferenceKind::kQuadric:
      return "quadric";
    case ReferenceKind::kCubic:
      return "cubic";
    case ReferenceKind::kBaseline:
      return "baseline";
  }
  return "unknown";
}

bool LesionMeasureParams::IsValid(std::string* error) const {
  if (!(ring_width_mm > 0.0 && std::isfinite(ring_width_mm)))
    return Fail(error, "lesion ring_width_mm must be positive and finite");
  if (!(level_fraction > 0.0 && level_fraction < 1.0))
    return Fail(error, "lesion level_fraction must lie in (0, 1)");
  if (!(peak_fit_radius_mm > 0.0 && std::isfinite(peak_fit_radius_mm)))
    return Fail(error, "lesion peak_fit_radius_mm must be positive and finite");
  if (!(huber_k > 0.0 && std::isfinite(huber_k)))
    return Fail(error, "lesion huber_k must be positive and finite");
  if (robust_iterations < 1) return Fail(error, "lesion robust_iterations must be at least 1");
  return true;
}

double ReferenceSurface::Z(const Eigen::Vector2d& xy) const {
  assert(coefficients.size() >= kPlaneTerms && "a baseline's description has no surface");
  return Basis(xy - origin, static_cast<int>(coefficients.size())).dot(coefficients);
}

Eigen::Vector2d ReferenceSurface::Gradient(const Eigen::Vector2d& xy) const {
  assert(coefficients.size() >= kPlaneTerms && "a baseline's description has no surface");
  Eigen::Vector2d g(coefficients[1], coefficients[2]);
  const Eigen::Vector2d d = xy - origin;
  if (coefficients.size() >= kQuadricTerms) {
    g.x() += 2.0 * coefficients[3] * d.x() + coefficients[4] * d.y();
    g.y() += coefficients[4] * d.x() + 2.0 * coefficients[5] * d.y();
  }
  if (coefficients.size() >= kCubicTerms) {
    g.x() += 3.0 * coefficients[6] * d.x() * d.x() + 2.0 * coefficients[7] * d.x() * d.y() +
             coefficients[8] * d.y() * d.y();
    g.y() += coefficients[7] * d.x() * d.x() + 2.0 * coefficients[8] * d.x() * d.y() +
             3.0 * coefficients[9] * d.y() * d.y();
  }
  return g;
}

double ReferenceSurface::SigmaZ(const Eigen::Vector2d& xy) const {
  assert(coefficients.size() >= kPlaneTerms && "a baseline's description has no surface");
  const Eigen::VectorXd phi = Basis(xy - origin, static_cast<int>(coefficients.size()));
  return std::sqrt(std::max(0.0, phi.dot(covariance * phi)));
}

ReferenceSurface FitReference(const SurfaceQuery& surface, const Polygon2d& region,
                              const LesionMeasureParams& params) {
  std::string why;
  if (!params.IsValid(&why)) throw MeasurementError(why);
  internal::CheckPolygon(region, "lesion region");
  if (params.reference == ReferenceKind::kBaseline)
    throw MeasurementError(
        "lesion reference: a baseline is an earlier scan, not a fit "
        "(MeasureLesionAgainstBaseline)");
  const geometry::SurfaceMesh& mesh = surface.mesh();
  const std::vector<int> ring_vertices = RingVertices(surface, region, params.ring_width_mm);
  const int terms = TermsOf(params.reference);
  if (static_cast<int>(ring_vertices.size()) < terms)
    throw MeasurementError("lesion reference: the ring of " + std::to_string(params.ring_width_mm) +
                           " mm around the region holds " + std::to_string(ring_vertices.size()) +
                           " surface vertices; a " + ToString(params.reference) +
                           " needs at least " + std::to_string(terms));
  ReferenceSurface reference;
  reference.kind = params.reference;
  reference.origin = internal::Centroid(region);
  reference.ring_vertices = static_cast<int>(ring_vertices.size());
  const int n = static_cast<int>(ring_vertices.size());
  Eigen::MatrixXd a(n, terms);
  Eigen::VectorXd z(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = mesh.positions[ring_vertices[i]];
    a.row(i) = Basis(p.head<2>() - reference.origin, terms).transpose();
    z[i] = p.z();
  }
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(n);
  Eigen::VectorXd residual(n);
  Eigen::MatrixXd normal;
  double sigma = 0.0;
  for (int round = 0; round < params.robust_iterations; ++round) {
    normal = a.transpose() * weights.asDiagonal() * a;
    const Eigen::LDLT<Eigen::MatrixXd> solver(normal);
    if (solver.info() != Eigen::Success || solver.rcond() < 1e-14)
      throw MeasurementError("lesion reference: the ring's vertices do not determine a " +
                             ToString(params.reference));
    reference.coefficients = solver.solve(a.transpose() * weights.asDiagonal() * z);
    residual = z - a * reference.coefficients;
    std::vector<double> magnitudes(n);
    for (int i = 0; i < n; ++i) magnitudes[i] = std::abs(residual[i]);
    sigma = std::max(kMadToSigma * Median(magnitudes), kMinRobustSigmaMm);
    const double threshold = params.huber_k * sigma;
    for (int i = 0; i < n; ++i)
      weights[i] = magnitudes[i] <= threshold ? 1.0 : threshold / magnitudes[i];
  }
  const double weight_sum = weights.sum();
  const double variance =
      residual.cwiseProduct(residual).dot(weights) / std::max(1.0, weight_sum - terms);
  reference.residual_rms_mm = std::sqrt(variance);
  reference.covariance =
      variance * Eigen::MatrixXd(normal).ldlt().solve(Eigen::MatrixXd::Identity(terms, terms));
  return reference;
}

namespace {

// The undisturbed surface a lesion is measured against: a fitted ring
// reference or a registered baseline scan.
struct ReferenceView {
  ReferenceKind kind = ReferenceKind::kCubic;
  std::function<std::optional<double>(const Eigen::Vector2d&)> z;   // nullopt: no surface there
  std::function<Eigen::Vector2d(const Eigen::Vector2d&)> gradient;  // (dz/dx, dz/dy)
  std::function<double(const Eigen::Vector2d&)> sigma;              // 1 sigma of z, mm
  double residual_rms_mm = 0.0;     // of the surface against it outside the region
  double noise_variance_mm2 = 0.0;  // of that residual explained by the reference's own noise
  double min_coverage = 1.0;        // share of the region it must lie under
};

// What every step of MeasureAgainst reads: the surface, the region (counter-
// clockwise), the params and the reference; and the deviations
// d = z - reference, each computed once on first use.
struct LesionScene {
  LesionScene(const SurfaceQuery& surface_in, const Polygon2d& region_in,
              const LesionMeasureParams& params_in, const ReferenceView& reference_in)
      : surface(surface_in),
        mesh(surface_in.mesh()),
        region(region_in),
        params(params_in),
        reference(reference_in),
        deviations(mesh.positions.size(), std::numeric_limits<double>::quiet_NaN()) {}

  // d at vertex v; infinite where the reference has no surface.
  double Deviation(int v) {
    if (std::isnan(deviations[v])) {
      const auto z = reference.z(mesh.positions[v].head<2>());
      deviations[v] = z ? mesh.positions[v].z() - *z : std::numeric_limits<double>::infinity();
    }
    return deviations[v];
  }

  const SurfaceQuery& surface;
  const geometry::SurfaceMesh& mesh;
  const Polygon2d& region;
  const LesionMeasureParams& params;
  const ReferenceView& reference;
  std::vector<double> deviations;  // NaN: not computed yet
};

// The vertices inside the region over the reference, their deviations
// stored; throws when there is none.
std::vector<int> InsideVertices(LesionScene& s, const Eigen::AlignedBox2d& box) {
  // Deviation d = z - reference (NaN where the reference has no surface).
  std::vector<int> inside;
  for (int v : CandidateVertices(s.surface, box)) {
    const Eigen::Vector2d xy = s.mesh.positions[v].head<2>();
    if (!internal::Contains(s.region, xy)) continue;
    if (const auto z = s.reference.z(xy)) {
      s.deviations[v] = s.mesh.positions[v].z() - *z;
      inside.push_back(v);
    }
  }
  if (inside.empty())
    throw MeasurementError(
        "lesion region: no surface vertex lies inside the polygon" +
        std::string(s.reference.kind == ReferenceKind::kBaseline ? " over the baseline" : ""));
  return inside;
}

// The lesion's peak: its extreme vertex and sign (+1 raised, -1 cavity), the
// peak's height sign * d (mm) and x-y position, and its fit's 1 sigma.
struct PeakEstimate {
  int extreme = 0;
  double sign = 1.0;
  double value = 0.0;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  double fit_sigma = 0.0;
};

// Replaces `peak`'s value, position and sigma by the maximum of a quadratic
// fitted to the window's sign * d around `centre`, when the fit is
// determined: 2-D, or 1-D along the stripe for a window holding one.
void FitPeakWindow(LesionScene& s, const std::vector<int>& window, const Eigen::Vector2d& centre,
                   PeakEstimate* peak) {
  const geometry::SurfaceMesh& mesh = s.mesh;
  const int n = static_cast<int>(window.size());
  // Principal direction of the window: along the stripe when it holds one.
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (int v : window) {
    const Eigen::Vector2d d = mesh.positions[v].head<2>() - centre;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> axes(scatter);
  const bool one_line = axes.eigenvalues()[0] < kCollinearRatio * axes.eigenvalues()[1];
  const Eigen::Vector2d along = axes.eigenvectors().col(1);
  // 2-D quadratic, or 1-D quadratic along the line for a collinear window.
  const int terms = one_line ? 3 : kQuadricTerms;
  auto basis = [&](const Eigen::Vector2d& d) {
    if (!one_line) return Basis(d, kQuadricTerms);
    const double t = d.dot(along);
    Eigen::VectorXd phi(3);
    phi << 1.0, t, t * t;
    return phi;
  };
  Eigen::MatrixXd a(n, terms);
  Eigen::VectorXd d(n);
  for (int i = 0; i < n; ++i) {
    a.row(i) = basis(mesh.positions[window[i]].head<2>() - centre).transpose();
    d[i] = peak->sign * s.Deviation(window[i]);
  }
  const Eigen::MatrixXd normal = a.transpose() * a;
  const Eigen::LDLT<Eigen::MatrixXd> solver(normal);
  if (!(solver.info() == Eigen::Success && solver.rcond() > 1e-14)) return;
  const Eigen::VectorXd c = solver.solve(a.transpose() * d);
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
  bool interior = false;
  if (one_line) {
    if (c[2] < 0.0) {
      offset = (-c[1] / (2.0 * c[2])) * along;
      interior = offset.norm() <= s.params.peak_fit_radius_mm;
    }
  } else {
    Eigen::Matrix2d hessian;
    hessian << 2.0 * c[3], c[4], c[4], 2.0 * c[5];
    if (hessian.determinant() > 0.0 && hessian(0, 0) < 0.0) {
      offset = hessian.ldlt().solve(-Eigen::Vector2d(c[1], c[2]));
      interior = offset.norm() <= s.params.peak_fit_radius_mm;
    }
  }
  if (!interior) {  // no maximum inside: the best fitted vertex
    double best = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      const double value = a.row(i).dot(c);
      if (value > best) {
        best = value;
        offset = mesh.positions[window[i]].head<2>() - centre;
      }
    }
  }
  const Eigen::VectorXd phi = basis(offset);
  peak->value = phi.dot(c);
  peak->xy = centre + offset;
  const Eigen::VectorXd r = d - a * c;
  const double variance = r.squaredNorm() / std::max(1, n - terms);
  peak->fit_sigma = std::sqrt(std::max(0.0, variance * phi.dot(solver.solve(phi))));
}

// Peak: sign from the extreme vertex, value from a quadratic around the top.
PeakEstimate EstimatePeak(LesionScene& s, const std::vector<int>& inside) {
  const geometry::SurfaceMesh& mesh = s.mesh;
  PeakEstimate peak;
  int extreme = inside.front();
  for (int v : inside)
    if (std::abs(s.Deviation(v)) > std::abs(s.Deviation(extreme))) extreme = v;
  peak.extreme = extreme;
  peak.sign = s.Deviation(extreme) >= 0.0 ? 1.0 : -1.0;
  const double sign = peak.sign;
  // The window is centred on the lesion's top (the centroid of the vertices
  // within kTopFraction of the extreme one), not on the extreme vertex:
  // that vertex lies on the stripe whose own error is largest, and a window
  // around it carries that error into the peak.
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  int top = 0;
  for (int v : inside)
    if (sign * s.Deviation(v) >= kTopFraction * std::abs(s.Deviation(extreme))) {
      centre += mesh.positions[v].head<2>();
      ++top;
    }
  centre /= static_cast<double>(top);
  std::vector<int> window;
  for (int v : inside)
    if ((mesh.positions[v].head<2>() - centre).norm() <= s.params.peak_fit_radius_mm)
      window.push_back(v);
  peak.value = sign * s.Deviation(extreme);
  peak.xy = centre;
  peak.fit_sigma = s.surface.VertexSigma(extreme);
  if (static_cast<int>(window.size()) > kQuadricTerms) FitPeakWindow(s, window, centre, &peak);
  return peak;
}

// Model misfit: the part of the ring's residual that the vertices' noise
// does not explain; the reference is assumed to miss by as much inside.
double ModelMisfit(const LesionScene& s, const std::vector<int>& inside) {
  double noise_variance = 0.0;
  for (int v : inside) noise_variance += std::pow(s.surface.VertexSigma(v), 2);
  noise_variance /= static_cast<double>(inside.size());
  return std::sqrt(std::max(0.0, s.reference.residual_rms_mm * s.reference.residual_rms_mm -
                                     noise_variance - s.reference.noise_variance_mm2));
}

// The x-y area of a triangle's part above the level inside the region; near
// the level, on a lattice following the stripes' cubic (see MeasureAgainst).
class LevelCut {
 public:
  LevelCut(const Polygon2d& region, const internal::StripeField& scan_field,
           const ReferenceView& reference, double sign, double level_mm)
      : region_(region),
        scan_field_(scan_field),
        reference_(reference),
        sign_(sign),
        level_mm_(level_mm) {}

  // The part of `triangle` (counter-clockwise, deviations `values`) above
  // the level inside the region (`whole`: the triangle lies in it), x-y mm^2.
  double RaisedXy(const Polygon2d& triangle, const std::vector<double>& values, bool whole) const {
    const Polygon2d raised = internal::ClipByLevel(triangle, values, level_mm_);
    if (raised.size() < 3) return 0.0;
    return std::abs(internal::SignedArea(whole ? raised : internal::ClipByConvex(region_, raised)));
  }

  // The same for a face whose deviations span [lo, hi].
  double Xy(const Polygon2d& triangle, const std::vector<double>& values, double lo, double hi,
            bool whole) const;

 private:
  const Polygon2d& region_;
  const internal::StripeField& scan_field_;
  const ReferenceView& reference_;
  double sign_;
  double level_mm_;
};

double LevelCut::Xy(const Polygon2d& triangle, const std::vector<double>& values, double lo,
                    double hi, bool whole) const {
  const double margin = kSubdivisionMargin * std::abs(level_mm_);
  if (scan_field_.empty() || hi < level_mm_ - margin || lo > level_mm_ + margin)
    return RaisedXy(triangle, values, whole);
  double longest = 0.0;
  for (int k = 0; k < 3; ++k)
    longest = std::max(longest, (triangle[(k + 1) % 3] - triangle[k]).norm());
  const int steps =
      std::clamp(static_cast<int>(std::ceil(longest / kSubdivisionMm)), 1, kMaxSubdivisions);
  // Lattice point (i, j) = t0 + (t1 - t0) i / steps + (t2 - t0) j / steps, row by row.
  std::vector<Eigen::Vector2d> points;
  std::vector<double> lattice;
  for (int i = 0; i <= steps; ++i)
    for (int j = 0; j <= steps - i; ++j) {
      const double u = static_cast<double>(i) / steps, v = static_cast<double>(j) / steps;
      const Eigen::Vector2d p =
          triangle[0] + (triangle[1] - triangle[0]) * u + (triangle[2] - triangle[0]) * v;
      double value = (1.0 - u - v) * values[0] + u * values[1] + v * values[2];
      if (const auto z = scan_field_.Z(p))
        if (const auto z_reference = reference_.z(p)) value = sign_ * (*z - *z_reference);
      points.push_back(p);
      lattice.push_back(value);
    }
  auto at = [&](int i, int j) { return i * (steps + 1) - i * (i - 1) / 2 + j; };
  double xy = 0.0;
  for (int i = 0; i < steps; ++i)
    for (int j = 0; i + j < steps; ++j) {
      const std::array<int, 3> lower = {at(i, j), at(i + 1, j), at(i, j + 1)};
      xy += RaisedXy({points[lower[0]], points[lower[1]], points[lower[2]]},
                     {lattice[lower[0]], lattice[lower[1]], lattice[lower[2]]}, whole);
      if (i + j + 1 < steps) {
        const std::array<int, 3> upper = {at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
        xy += RaisedXy({points[upper[0]], points[upper[1]], points[upper[2]]},
                       {lattice[upper[0]], lattice[upper[1]], lattice[upper[2]]}, whole);
      }
    }
  return xy;
}

// Sums over the region's faces: area at the level, volume, the x-y area
// with and without reference under it, and what the level line's position
// uncertainty contributes to the area's.
struct RegionIntegrals {
  double area = 0.0, volume = 0.0, covered_xy = 0.0, uncovered_xy = 0.0;
  double boundary_ref = 0.0, boundary_length = 0.0, boundary_noise = 0.0;
  std::vector<double> volume_weight;  // per vertex, mm^2
  bool any_face = false;
};

// Adds the level line through one face (counter-clockwise `triangle`,
// vertices `ids`, sign * d `values`) to the boundary sums, when it crosses
// the face with its middle inside the region.
void AddLevelLine(const LesionScene& s, const Polygon2d& triangle, const std::array<int, 3>& ids,
                  const std::vector<double>& values, double level_mm, double misfit,
                  RegionIntegrals* sums) {
  std::vector<Eigen::Vector2d> crossings;
  for (int k = 0; k < 3; ++k) {
    const double va = values[k] - level_mm, vb = values[(k + 1) % 3] - level_mm;
    if ((va >= 0.0) != (vb >= 0.0))
      crossings.push_back(triangle[k] + (triangle[(k + 1) % 3] - triangle[k]) * (va / (va - vb)));
  }
  if (crossings.size() != 2) return;
  const Eigen::Vector2d middle = 0.5 * (crossings[0] + crossings[1]);
  if (!internal::Contains(s.region, middle)) return;
  Eigen::Matrix2d e;
  e.col(0) = triangle[1] - triangle[0];
  e.col(1) = triangle[2] - triangle[0];
  const Eigen::Vector2d slope =
      e.transpose().inverse() * Eigen::Vector2d(values[1] - values[0], values[2] - values[0]);
  const double per_mm = (crossings[1] - crossings[0]).norm() / std::max(slope.norm(), 1e-9) *
                        std::sqrt(1.0 + s.reference.gradient(middle).squaredNorm());
  const double vertex_sigma = (s.surface.VertexSigma(ids[0]) + s.surface.VertexSigma(ids[1]) +
                               s.surface.VertexSigma(ids[2])) /
                              3.0;
  sums->boundary_length += per_mm;
  sums->boundary_ref += per_mm * std::hypot(s.reference.sigma(middle), misfit);
  sums->boundary_noise += std::pow(per_mm * vertex_sigma, 2);
}

// Area at the level, volume over the region.
RegionIntegrals IntegrateRegion(LesionScene& s, const std::vector<int>& faces_in_box,
                                const LevelCut& cut, double sign, double level_mm, double misfit) {
  const geometry::SurfaceMesh& mesh = s.mesh;
  RegionIntegrals sums;
  sums.volume_weight.assign(mesh.positions.size(), 0.0);
  for (int f : faces_in_box) {
    const Eigen::Vector3i& face = mesh.faces[f];
    std::array<int, 3> ids = {face[0], face[1], face[2]};
    Polygon2d triangle = {mesh.positions[ids[0]].head<2>(), mesh.positions[ids[1]].head<2>(),
                          mesh.positions[ids[2]].head<2>()};
    const double signed_xy = internal::SignedArea(triangle);
    if (std::abs(signed_xy) < 1e-12) continue;
    if (signed_xy < 0.0) {
      std::swap(triangle[1], triangle[2]);
      std::swap(ids[1], ids[2]);
    }
    const Polygon2d piece = internal::ClipByConvex(s.region, triangle);
    const double piece_xy = std::abs(internal::SignedArea(piece));
    if (piece_xy <= 0.0) continue;
    const std::vector<double> values = {sign * s.Deviation(ids[0]), sign * s.Deviation(ids[1]),
                                        sign * s.Deviation(ids[2])};
    if (!std::isfinite(values[0] + values[1] + values[2])) {  // no reference under a vertex
      sums.uncovered_xy += piece_xy;
      continue;
    }
    sums.covered_xy += piece_xy;
    sums.any_face = true;
    const Eigen::Vector3d w =
        internal::Barycentric(triangle[0], triangle[1], triangle[2], internal::Centroid(piece));
    sums.volume += piece_xy * (w[0] * values[0] + w[1] * values[1] + w[2] * values[2]);
    for (int k = 0; k < 3; ++k) sums.volume_weight[ids[k]] += piece_xy * w[k];

    const double lo = *std::min_element(values.begin(), values.end());
    const double hi = *std::max_element(values.begin(), values.end());
    const bool whole = piece_xy >= (1.0 - 1e-9) * std::abs(signed_xy);
    if (const double part_xy = cut.Xy(triangle, values, lo, hi, whole); part_xy > 0.0)
      sums.area +=
          part_xy * std::sqrt(1.0 + s.reference.gradient(internal::Centroid(piece)).squaredNorm());
    // The level line through this face: its length over the slope of d says
    // how much area a shift of the level moves.
    if (lo < level_mm && hi > level_mm)
      AddLevelLine(s, triangle, ids, values, level_mm, misfit, &sums);
  }
  return sums;
}

// sign * d sampled on `field`'s grid (covering `grid_box`) at every cell
// centre a face with a reference under all its vertices covers.
void SampleDeviationGrid(LesionScene& s, const Eigen::AlignedBox2d& grid_box, double sign,
                         internal::GridField* field) {
  const geometry::SurfaceMesh& mesh = s.mesh;
  const double cell = field->cell_mm;
  for (int f : s.surface.FacesIn(grid_box)) {
    const Eigen::Vector3i& face = mesh.faces[f];
    const std::array<double, 3> values = {sign * s.Deviation(face[0]), sign * s.Deviation(face[1]),
                                          sign * s.Deviation(face[2])};
    if (!std::isfinite(values[0] + values[1] + values[2])) continue;
    const Eigen::Vector2d a = mesh.positions[face[0]].head<2>(),
                          b = mesh.positions[face[1]].head<2>(),
                          c = mesh.positions[face[2]].head<2>();
    if (std::abs(internal::SignedArea({a, b, c})) < 1e-12) continue;
    const Eigen::Vector2d lo = (a.cwiseMin(b).cwiseMin(c) - field->origin) / cell;
    const Eigen::Vector2d hi = (a.cwiseMax(b).cwiseMax(c) - field->origin) / cell;
    for (int r = std::max(0, static_cast<int>(std::floor(lo.y())));
         r <= std::min(field->rows - 1, static_cast<int>(std::ceil(hi.y()))); ++r)
      for (int col = std::max(0, static_cast<int>(std::floor(lo.x())));
           col <= std::min(field->cols - 1, static_cast<int>(std::ceil(hi.x()))); ++col) {
        const int index = r * field->cols + col;
        const Eigen::Vector3d w = internal::Barycentric(a, b, c, field->Centre(index));
        if (w.minCoeff() < -1e-9) continue;
        field->value[index] = w[0] * values[0] + w[1] * values[1] + w[2] * values[2];
      }
  }
}

// The holes the measured surface encloses, filled: sign * d sampled on a
// grid where a face covers a cell's centre, interpolated over each hole
// (thin plate; the membrane's answer gives the spread), and the hole cells
// inside the region added to the area and the volume. Sets result's filled
// figures; they equal the measured ones for a region too wide to fill.
void FillRegionHoles(LesionScene& s, const Eigen::AlignedBox2d& box, double sign, double area,
                     double volume, double region_xy, LesionMeasurement& result) {
  internal::GridField field;
  field.origin = box.min() - Eigen::Vector2d::Constant(kFillMarginMm);
  const Eigen::Vector2d extent = box.sizes() + Eigen::Vector2d::Constant(2.0 * kFillMarginMm);
  result.filled_area_mm2 = result.area_mm2;
  result.filled_volume_mm3 = result.volume_mm3;
  if (!(extent.maxCoeff() <= kMaxFillExtentMm)) return;
  const double cell =
      std::max(kFillCellMm, std::sqrt(extent.x()) * std::sqrt(extent.y() / kMaxFillCells));
  field.cell_mm = cell;
  field.cols = static_cast<int>(std::ceil(extent.x() / cell));
  field.rows = static_cast<int>(std::ceil(extent.y() / cell));
  field.value.assign(static_cast<std::size_t>(field.cols) * field.rows,
                     std::numeric_limits<double>::quiet_NaN());
  const std::vector<char> in_region = internal::InsideMask(field, s.region);
  const Eigen::AlignedBox2d grid_box(field.origin, field.origin + extent);
  SampleDeviationGrid(s, grid_box, sign, &field);
  // Outside the region the face is undisturbed (the premise of the region
  // and of its reference): d = 0 where no face covers a cell there, so that
  // a hole reaching the region's boundary is enclosed too.
  for (std::size_t i = 0; i < field.value.size(); ++i)
    if (std::isnan(field.value[i]) && !in_region[i]) field.value[i] = 0.0;
  const internal::FilledField filled = internal::FillHoles(field);
  const std::vector<double>& plate = filled.thin_plate;
  const std::vector<double>& membrane = filled.membrane;
  double plate_area = 0.0, plate_volume = 0.0, membrane_area = 0.0, membrane_volume = 0.0,
         filled_xy = 0.0;
  const double cell_xy = cell * cell;
  for (std::size_t i = 0; i < field.value.size(); ++i) {
    // Measured, outside, or open to the grid's border (cells wider than the margin).
    if (!std::isnan(field.value[i]) || !in_region[i] || std::isnan(plate[i])) continue;
    const Eigen::Vector2d xy = field.Centre(static_cast<int>(i));
    const double slant = std::sqrt(1.0 + s.reference.gradient(xy).squaredNorm());
    filled_xy += cell_xy;
    plate_volume += cell_xy * plate[i];
    membrane_volume += cell_xy * membrane[i];
    if (plate[i] >= result.level_mm) plate_area += cell_xy * slant;
    if (membrane[i] >= result.level_mm) membrane_area += cell_xy * slant;
  }
  result.filled_share = filled_xy / region_xy;
  result.filled_area_mm2 = {area + plate_area,
                            std::hypot(result.area_mm2.uncertainty, plate_area - membrane_area)};
  result.filled_volume_mm3 = {volume + plate_volume, std::hypot(result.volume_mm3.uncertainty,
                                                                plate_volume - membrane_volume)};
}

// Peak, area at the level and volume of the lesion in `region` (counter-
// clockwise) against `reference`; fills every figure of `result` but the
// reference's description.
void MeasureAgainst(const SurfaceQuery& surface, const Polygon2d& region,
                    const LesionMeasureParams& params, const ReferenceView& reference,
                    LesionMeasurement* result_out) {
  LesionMeasurement& result = *result_out;
  LesionScene s(surface, region, params, reference);
  const geometry::SurfaceMesh& mesh = s.mesh;
  const Eigen::AlignedBox2d box = internal::Bounds(region);
  const std::vector<int> inside = InsideVertices(s, box);
  result.region_vertices = static_cast<int>(inside.size());

  const PeakEstimate peak = EstimatePeak(s, inside);
  const double sign = peak.sign;
  result.cavity = sign < 0.0;
  const double misfit = ModelMisfit(s, inside);
  result.peak_mm.value = peak.value;
  result.peak_mm.uncertainty = std::sqrt(peak.fit_sigma * peak.fit_sigma +
                                         std::pow(reference.sigma(peak.xy), 2) + misfit * misfit);
  const double reference_z =
      reference.z(peak.xy).value_or(mesh.positions[peak.extreme].z() - s.Deviation(peak.extreme));
  result.peak_position = Eigen::Vector3d(peak.xy.x(), peak.xy.y(), reference_z + sign * peak.value);
  result.level_mm = params.level_fraction * peak.value;

  // The level cut: between the stripes the deviation follows the cubic of
  // StripeField, not the mesh's flat triangles (a linear cut between
  // stripes 5.7 mm apart shrinks the thesis's cheek cavity by 2 to 3 %,
  // and by a different amount for each way of splitting the strips into
  // triangles). The faces whose values come near the level are cut on a
  // lattice of kSubdivisionMm; the others, and meshes without stripe
  // labels, linearly.
  const std::vector<int> faces_in_box = surface.FacesIn(box);
  const internal::StripeField scan_field(mesh,
                                         surface.FacesIn(internal::Grown(box, kFieldMarginMm)));
  const LevelCut cut(region, scan_field, reference, sign, result.level_mm);

  // Area at the level, volume over the region.
  const RegionIntegrals sums = IntegrateRegion(s, faces_in_box, cut, sign, result.level_mm, misfit);
  if (!sums.any_face) throw MeasurementError("lesion region: no surface lies inside the polygon");
  const double coverage = sums.covered_xy / (sums.covered_xy + sums.uncovered_xy);
  result.surface_coverage =
      std::min(1.0, (sums.covered_xy + sums.uncovered_xy) / std::abs(internal::SignedArea(region)));
  if (coverage < reference.min_coverage)
    throw MeasurementError("lesion region: the baseline lies under only " +
                           std::to_string(static_cast<int>(std::floor(100.0 * coverage))) +
                           " % of the surface in the polygon");
  result.area_mm2.value = sums.area;
  result.area_mm2.uncertainty = std::sqrt(
      sums.boundary_ref * sums.boundary_ref + sums.boundary_noise +
      std::pow(sums.boundary_length * params.level_fraction * result.peak_mm.uncertainty, 2));
  double volume_variance = 0.0;
  for (std::size_t v = 0; v < sums.volume_weight.size(); ++v)
    if (sums.volume_weight[v] > 0.0)
      volume_variance +=
          std::pow(sums.volume_weight[v] * surface.VertexSigma(static_cast<int>(v)), 2);
  const double region_xy = std::abs(internal::SignedArea(region));
  volume_variance += std::pow(region_xy * reference.sigma(internal::Centroid(region)), 2);
  result.volume_mm3.value = sums.volume;
  result.volume_mm3.uncertainty = std::sqrt(volume_variance);
  result.region_area_mm2 = SurfaceArea(surface, region);

  FillRegionHoles(s, box, sign, sums.area, sums.volume, region_xy, result);
}

// `region` checked and counter-clockwise.
Polygon2d OrientedRegion(const Polygon2d& region_in) {
  Polygon2d region = region_in;
  internal::CheckPolygon(region, "lesion region");
  if (internal::SignedArea(region) < 0.0) std::reverse(region.begin(), region.end());
  return region;
}

}  // namespace

LesionMeasurement MeasureLesion(const SurfaceQuery& surface, const Polygon2d& region_in,
                                const LesionMeasureParams& params) {
  const Polygon2d region = OrientedRegion(region_in);
  LesionMeasurement result;
  result.reference = FitReference(surface, region, params);
  const ReferenceSurface& fitted = result.reference;
  ReferenceView view;
  view.kind = fitted.kind;
  view.z = [&](const Eigen::Vector2d& xy) { return std::optional<double>(fitted.Z(xy)); };
  view.gradient = [&](const Eigen::Vector2d& xy) { return fitted.Gradient(xy); };
  view.sigma = [&](const Eigen::Vector2d& xy) { return fitted.SigmaZ(xy); };
  view.residual_rms_mm = fitted.residual_rms_mm;
  MeasureAgainst(surface, region, params, view, &result);
  return result;
}

LesionMeasurement MeasureLesionAgainstBaseline(const SurfaceQuery& surface,
                                               const geometry::SurfaceMesh& baseline,
                                               const Polygon2d& region_in,
                                               const LesionMeasureParams& params,
                                               const BaselineParams& baseline_params) {
  std::string why;
  if (!params.IsValid(&why)) throw MeasurementError(why);
  const Polygon2d region = OrientedRegion(region_in);
  std::optional<SurfaceQuery> original;
  try {
    original.emplace(baseline);
  } catch (const MeasurementError& e) {
    throw MeasurementError(std::string("baseline: ") + e.what());
  }
  LesionMeasurement result;
  result.baseline = RegisterToBaseline(surface, *original, region, baseline_params);
  // The baseline moved into this surface's frame, where the region is drawn.
  geometry::SurfaceMesh moved = baseline;
  const Eigen::Isometry3d to_surface = result.baseline->transform.inverse();
  for (Eigen::Vector3d& p : moved.positions) p = to_surface * p;
  for (Eigen::Vector3d& n : moved.normals) n = to_surface.linear() * n;
  const SurfaceQuery reference(moved);
  double mean_variance = 0.0;
  for (std::size_t v = 0; v < moved.positions.size(); ++v)
    mean_variance += std::pow(reference.VertexSigma(static_cast<int>(v)), 2);
  mean_variance /= static_cast<double>(std::max<std::size_t>(1, moved.positions.size()));

  // Between its stripes the baseline follows the same cubic as the surface
  // (StripeField), where it has stripe labels.
  const internal::StripeField baseline_field(
      moved, reference.FacesIn(
                 internal::Grown(internal::Bounds(region), params.ring_width_mm + kFieldMarginMm)));
  ReferenceView view;
  view.kind = ReferenceKind::kBaseline;
  view.z = [&](const Eigen::Vector2d& xy) -> std::optional<double> {
    const auto point = reference.Above(xy);
    if (!point) return std::nullopt;
    return baseline_field.Z(xy).value_or(point->position.z());
  };
  view.gradient = [&](const Eigen::Vector2d& xy) -> Eigen::Vector2d {
    const auto point = reference.Above(xy);
    if (!point) return Eigen::Vector2d::Zero();
    const Eigen::Vector3d n = reference.FaceNormal(point->face);
    if (std::abs(n.z()) < 1e-12) return Eigen::Vector2d::Zero();
    return Eigen::Vector2d(-n.x() / n.z(), -n.y() / n.z());
  };
  view.sigma = [&](const Eigen::Vector2d& xy) {
    const auto point = reference.Above(xy);
    if (!point) return std::sqrt(mean_variance);
    return std::hypot(point->sigma_mm, reference.InterpolationError(*point));
  };
  // How the surface departs from the baseline around the region: both scans'
  // noise plus what registration and resampling leave (robust RMS: the ring
  // may graze the lesion's skirt).
  std::vector<double> ring;
  double ring_noise = 0.0;
  for (int v : RingVertices(surface, region, params.ring_width_mm)) {
    const Eigen::Vector3d& p = surface.mesh().positions[v];
    if (const auto z = view.z(p.head<2>())) {
      ring.push_back(p.z() - *z);
      ring_noise += std::pow(view.sigma(p.head<2>()), 2);
    }
  }
  ReferenceSurface& described = result.reference;
  described.kind = ReferenceKind::kBaseline;
  described.origin = internal::Centroid(region);
  described.ring_vertices = static_cast<int>(ring.size());
  if (!ring.empty()) {
    std::vector<double> magnitudes;
    for (double d : ring) magnitudes.push_back(std::abs(d));
    const double robust = std::max(kMadToSigma * Median(magnitudes), kMinRobustSigmaMm);
    double sum = 0.0;
    int kept = 0;
    for (double d : ring)
      if (std::abs(d) <= 3.0 * robust) {
        sum += d * d;
        ++kept;
      }
    described.residual_rms_mm = std::sqrt(sum / std::max(kept, 1));
    view.noise_variance_mm2 = ring_noise / static_cast<double>(ring.size());
  }
  view.residual_rms_mm = described.residual_rms_mm;
  view.min_coverage = baseline_params.min_coverage;
  MeasureAgainst(surface, region, params, view, &result);
  return result;
}

}  // namespace bsls::measurement
