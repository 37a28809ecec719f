#include "bsls/joining/stripe_curve.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace bsls::joining {

std::vector<Eigen::Vector3d> VertexNormals(const geometry::SurfaceMesh& mesh) {
  if (!mesh.normals.empty()) return mesh.normals;
  if (mesh.faces.empty()) return {};
  std::vector<Eigen::Vector3d> normals(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d n = (mesh.positions[f[1]] - mesh.positions[f[0]])
                                  .cross(mesh.positions[f[2]] - mesh.positions[f[0]]);
    for (int k = 0; k < 3; ++k) normals[f[k]] += n;
  }
  for (Eigen::Vector3d& n : normals) {
    if (n.norm() > 0.0) n.normalize();
  }
  return normals;
}

StripeCurve StripeCurve::FromMesh(const geometry::SurfaceMesh& mesh, int p, double max_gap_mm) {
  StripeCurve curve;
  if (mesh.line.size() != mesh.positions.size()) return curve;
  std::vector<int> order;
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    if (mesh.line[v] == p && mesh.positions[v].allFinite()) order.push_back(static_cast<int>(v));
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return mesh.positions[a].y() > mesh.positions[b].y(); });
  const std::vector<Eigen::Vector3d> normals = VertexNormals(mesh);
  for (int v : order) {
    curve.points_.push_back(mesh.positions[v]);
    curve.vertices_.push_back(v);
    if (!normals.empty()) curve.normals_.push_back(normals[v]);
  }
  for (std::size_t i = 0; i + 1 < curve.points_.size(); ++i) {
    curve.joined_.push_back((curve.points_[i + 1] - curve.points_[i]).norm() <= max_gap_mm);
  }
  curve.ComputeBounds();
  return curve;
}

void StripeCurve::ComputeBounds() {
  bounds_.clear();
  for (std::size_t first = 0; first + 1 < points_.size(); first += kChunk) {
    const std::size_t last = std::min(first + kChunk, points_.size() - 1);
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (std::size_t i = first; i <= last; ++i) centre += points_[i];
    centre /= static_cast<double>(last - first + 1);
    double radius = 0.0;
    for (std::size_t i = first; i <= last; ++i)
      radius = std::max(radius, (points_[i] - centre).norm());
    bounds_.push_back({centre, radius});
  }
}

std::optional<CurvePoint> StripeCurve::Closest(const Eigen::Vector3d& query,
                                               double max_distance_mm) const {
  double best = std::numeric_limits<double>::infinity();
  std::size_t best_segment = 0;
  double best_s = 0.0;
  for (std::size_t c = 0; c < bounds_.size(); ++c) {
    // No point of the chunk's segments lies nearer than this: skipping it
    // changes nothing (a tie keeps the earlier segment either way).
    const double lower = (query - bounds_[c].centre).norm() - bounds_[c].radius;
    if (lower > max_distance_mm || (lower > 0.0 && lower * lower >= best)) continue;
    const std::size_t end = std::min((c + 1) * kChunk, points_.size() - 1);
    for (std::size_t i = c * kChunk; i < end; ++i) {
      if (!joined_[i]) continue;
      const Eigen::Vector3d d = points_[i + 1] - points_[i];
      const double length2 = d.squaredNorm();
      const double s =
          length2 > 0.0 ? std::clamp((query - points_[i]).dot(d) / length2, 0.0, 1.0) : 0.0;
      const double distance = (points_[i] + s * d - query).squaredNorm();
      if (distance < best) {
        best = distance;
        best_segment = i;
        best_s = s;
      }
    }
  }
  if (!std::isfinite(best) || std::sqrt(best) > max_distance_mm) return std::nullopt;
  const std::size_t i = best_segment;
  const bool run_start = i == 0 || !joined_[i - 1];
  const bool run_end = i + 2 >= points_.size() || !joined_[i + 1];
  if ((run_start && best_s <= 0.0) || (run_end && best_s >= 1.0)) return std::nullopt;
  CurvePoint result;
  const Eigen::Vector3d d = points_[i + 1] - points_[i];
  result.point = points_[i] + best_s * d;
  if (d.norm() > 0.0) result.tangent = d.normalized();
  if (!normals_.empty()) {
    const Eigen::Vector3d n = (1.0 - best_s) * normals_[i] + best_s * normals_[i + 1];
    if (n.norm() > 0.0) result.normal = n.normalized();
  }
  result.distance_mm = std::sqrt(best);
  return result;
}

StripeCurve StripeCurve::Transformed(const Eigen::Isometry3d& transform) const {
  StripeCurve moved = *this;
  for (Eigen::Vector3d& p : moved.points_) p = transform * p;
  for (Eigen::Vector3d& n : moved.normals_) n = transform.linear() * n;
  moved.ComputeBounds();
  return moved;
}

}  // namespace bsls::joining
