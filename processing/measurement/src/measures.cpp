#include "bsls/measurement/measures.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>

#include "polygon.h"

namespace bsls::measurement {
namespace {

// Faces flatter than this in x-y (|n_z|) are seen edge-on from above.
constexpr double kMinNormalZ = 1e-9;

// Gradient of the area of triangle (a, b, c) with respect to each vertex.
std::array<Eigen::Vector3d, 3> AreaGradient(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                            const Eigen::Vector3d& c) {
  Eigen::Vector3d n = (b - a).cross(c - a);
  const double norm = n.norm();
  if (norm == 0.0)
    return {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  n /= norm;
  // dA/dv_i = 0.5 * (v_{i+1} - v_{i+2}) x n.
  return {0.5 * (b - c).cross(n), 0.5 * (c - a).cross(n), 0.5 * (a - b).cross(n)};
}

// Combines per-vertex area gradients into a 1-sigma uncertainty.
double PropagateArea(const geometry::SurfaceMesh& mesh,
                     const std::vector<Eigen::Vector3d>& gradient,
                     const std::vector<int>& touched) {
  if (mesh.uncertainty_mm.empty()) return 0.0;
  double variance = 0.0;
  for (int v : touched)
    variance += gradient[v].squaredNorm() * std::pow(double{mesh.uncertainty_mm[v]}, 2);
  return std::sqrt(variance);
}

}  // namespace

Eigen::Vector3d ReferencePlane::Normal() const {
  return Eigen::Vector3d(-coefficients[1], -coefficients[2], 1.0).normalized();
}

double ReferencePlane::Z(const Eigen::Vector2d& xy) const {
  const Eigen::Vector2d d = xy - origin;
  return coefficients[0] + coefficients[1] * d.x() + coefficients[2] * d.y();
}

double ReferencePlane::SigmaZ(const Eigen::Vector2d& xy) const {
  const Eigen::Vector2d d = xy - origin;
  const Eigen::Vector3d phi(1.0, d.x(), d.y());
  return std::sqrt(std::max(0.0, phi.dot(covariance * phi)));
}

ReferencePlane FitReferencePlane(const SurfaceQuery& surface, const Polygon2d& region) {
  internal::CheckPolygon(region, "reference plane region");
  const geometry::SurfaceMesh& mesh = surface.mesh();
  const Eigen::AlignedBox2d box = internal::Bounds(region);
  std::vector<int> inside;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector2d xy = mesh.positions[v].head<2>();
    if (box.contains(xy) && internal::Contains(region, xy)) inside.push_back(static_cast<int>(v));
  }
  if (inside.size() < 3)
    throw MeasurementError("reference plane region holds " + std::to_string(inside.size()) +
                           " surface vertices; at least 3 are needed");
  ReferencePlane plane;
  plane.origin = internal::Centroid(region);
  Eigen::MatrixXd a(inside.size(), 3);
  Eigen::VectorXd z(inside.size());
  for (std::size_t i = 0; i < inside.size(); ++i) {
    const Eigen::Vector3d& p = mesh.positions[inside[i]];
    a.row(i) << 1.0, p.x() - plane.origin.x(), p.y() - plane.origin.y();
    z[i] = p.z();
  }
  const Eigen::Matrix3d normal = a.transpose() * a;
  const Eigen::LDLT<Eigen::Matrix3d> solver(normal);
  if (solver.info() != Eigen::Success || solver.rcond() < 1e-12)
    throw MeasurementError("reference plane region: its vertices are collinear");
  plane.coefficients = solver.solve(a.transpose() * z);
  const Eigen::VectorXd residual = z - a * plane.coefficients;
  plane.vertices = static_cast<int>(inside.size());
  plane.residual_rms_mm = std::sqrt(residual.squaredNorm() / inside.size());
  const double dof = std::max<double>(1.0, static_cast<double>(inside.size()) - 3.0);
  plane.covariance = residual.squaredNorm() / dof * solver.solve(Eigen::Matrix3d::Identity());
  return plane;
}

Measured HeightAboveBase(const SurfaceQuery& surface, const Eigen::Vector2d& xy) {
  const SurfacePoint point = surface.At(xy, "height point");
  const double discretisation = surface.InterpolationError(point);
  return {point.position.z(), std::hypot(point.sigma_mm, discretisation)};
}

Measured HeightAbovePlane(const SurfaceQuery& surface, const Eigen::Vector2d& xy,
                          const ReferencePlane& plane) {
  const SurfacePoint point = surface.At(xy, "height point");
  const Eigen::Vector3d normal = plane.Normal();
  const double along = normal.dot(point.position - Eigen::Vector3d(xy.x(), xy.y(), plane.Z(xy)));
  const double discretisation = surface.InterpolationError(point);
  // Vertical errors of point and plane project onto the normal with n_z.
  const double sigma =
      std::sqrt(std::pow(point.sigma_mm, 2) + std::pow(normal.z() * discretisation, 2) +
                std::pow(normal.z() * plane.SigmaZ(xy), 2));
  return {along, sigma};
}

Measured StraightDistance(const SurfaceQuery& surface, const Eigen::Vector2d& a_xy,
                          const Eigen::Vector2d& b_xy) {
  const SurfacePoint a = surface.At(a_xy, "distance start");
  const SurfacePoint b = surface.At(b_xy, "distance end");
  const Eigen::Vector3d d = b.position - a.position;
  const double length = d.norm();
  // Interpolation errors are vertical: they change the length by dz * d_z / |d|.
  const double slope = length > 0.0 ? std::abs(d.z()) / length : 1.0;
  const double sigma = std::sqrt(a.sigma_mm * a.sigma_mm + b.sigma_mm * b.sigma_mm +
                                 std::pow(slope * surface.InterpolationError(a), 2) +
                                 std::pow(slope * surface.InterpolationError(b), 2));
  return {length, sigma};
}

Measured SurfaceArea(const SurfaceQuery& surface, const Polygon2d& region_in) {
  internal::CheckPolygon(region_in, "area region");
  Polygon2d region = region_in;
  if (internal::SignedArea(region) < 0.0) std::reverse(region.begin(), region.end());
  const geometry::SurfaceMesh& mesh = surface.mesh();
  std::vector<Eigen::Vector3d> gradient(mesh.positions.size(), Eigen::Vector3d::Zero());
  std::vector<int> touched;
  double area = 0.0;
  for (int f : surface.FacesIn(internal::Bounds(region))) {
    const Eigen::Vector3i& face = mesh.faces[f];
    const Eigen::Vector3d& a = mesh.positions[face[0]];
    const Eigen::Vector3d& b = mesh.positions[face[1]];
    const Eigen::Vector3d& c = mesh.positions[face[2]];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() == 0.0 || std::abs(n.z()) / n.norm() < kMinNormalZ) continue;
    Polygon2d triangle = {a.head<2>(), b.head<2>(), c.head<2>()};
    if (internal::SignedArea(triangle) < 0.0) std::swap(triangle[1], triangle[2]);
    const double triangle_xy = std::abs(internal::SignedArea(triangle));
    const double piece_xy =
        std::abs(internal::SignedArea(internal::ClipByConvex(region, triangle)));
    if (piece_xy <= 0.0) continue;
    const double fraction = std::min(1.0, piece_xy / triangle_xy);
    area += fraction * 0.5 * n.norm();
    const auto g = AreaGradient(a, b, c);
    for (int k = 0; k < 3; ++k) {
      gradient[face[k]] += fraction * g[k];
      touched.push_back(face[k]);
    }
  }
  if (area <= 0.0) throw MeasurementError("area region: no surface lies inside the polygon");
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  return {area, PropagateArea(mesh, gradient, touched)};
}

Measured FacesArea(const geometry::SurfaceMesh& mesh, const std::vector<int>& faces) {
  if (faces.empty()) throw MeasurementError("face area: the face list is empty");
  std::string why;
  if (!mesh.IsValid(&why)) throw MeasurementError("face area: " + why);
  std::vector<Eigen::Vector3d> gradient(mesh.positions.size(), Eigen::Vector3d::Zero());
  std::vector<int> touched;
  double area = 0.0;
  for (int f : faces) {
    if (f < 0 || static_cast<std::size_t>(f) >= mesh.faces.size())
      throw MeasurementError("face area: face " + std::to_string(f) + " of " +
                             std::to_string(mesh.faces.size()) + " does not exist");
    const Eigen::Vector3i& face = mesh.faces[f];
    const Eigen::Vector3d& a = mesh.positions[face[0]];
    const Eigen::Vector3d& b = mesh.positions[face[1]];
    const Eigen::Vector3d& c = mesh.positions[face[2]];
    area += 0.5 * (b - a).cross(c - a).norm();
    const auto g = AreaGradient(a, b, c);
    for (int k = 0; k < 3; ++k) {
      gradient[face[k]] += g[k];
      touched.push_back(face[k]);
    }
  }
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  return {area, PropagateArea(mesh, gradient, touched)};
}

}  // namespace bsls::measurement
