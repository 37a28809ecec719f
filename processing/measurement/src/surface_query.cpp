#include "bsls/measurement/surface_query.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "polygon.h"

namespace bsls::measurement {
namespace {

// A face whose bounding box spans more grid cells than this along either
// axis is kept in a list of its own and tested by every query: a vertex
// thrown far away by a damaged file then costs one test per query, not a
// grid as large as its distance.
constexpr std::int64_t kMaxCellsPerFace = 16;
// Cell indices are clamped to this (a coordinate of 1e30 mm must not
// overflow the key).
constexpr double kMaxCellIndex = 1 << 30;

std::uint64_t KeyOf(std::int64_t x, std::int64_t y) {
  return (static_cast<std::uint64_t>(x) << 32) ^ (static_cast<std::uint64_t>(y) & 0xffffffffu);
}

// Barycentric slack (a point on an edge belongs to both faces).
constexpr double kInsideTolerance = 1e-9;
// The quadric of InterpolationError uses vertices within this many longest
// edges of the face.
constexpr double kInterpolationNeighbourhood = 1.5;

}  // namespace

SurfaceQuery::SurfaceQuery(const geometry::SurfaceMesh& mesh, double cell_mm) : mesh_(mesh) {
  std::string why;
  if (!mesh.IsValid(&why)) throw MeasurementError("surface: " + why);
  if (mesh.faces.empty()) throw MeasurementError("surface: the mesh has no faces");
  std::vector<double> edges;
  edges.reserve(mesh.faces.size() * 3);
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& p = mesh.positions[f[k]];
      if (!p.allFinite())
        throw MeasurementError("surface: vertex " + std::to_string(f[k]) + " is not finite");
      bounds_.extend(p.head<2>());
      edges.push_back((mesh.positions[f[(k + 1) % 3]] - p).norm());
    }
  }
  std::nth_element(edges.begin(), edges.begin() + edges.size() / 2, edges.end());
  median_edge_mm_ = std::max(edges[edges.size() / 2], 1e-6);
  cell_mm_ = cell_mm > 0.0 ? cell_mm : 2.0 * median_edge_mm_;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    Eigen::AlignedBox2d box;
    for (int k = 0; k < 3; ++k) box.extend(mesh.positions[mesh.faces[f][k]].head<2>());
    const std::int64_t x0 = CellOf(box.min().x()), x1 = CellOf(box.max().x());
    const std::int64_t y0 = CellOf(box.min().y()), y1 = CellOf(box.max().y());
    if (x1 - x0 >= kMaxCellsPerFace || y1 - y0 >= kMaxCellsPerFace) {
      large_faces_.push_back(static_cast<int>(f));
      continue;
    }
    for (std::int64_t y = y0; y <= y1; ++y)
      for (std::int64_t x = x0; x <= x1; ++x) cells_[KeyOf(x, y)].push_back(static_cast<int>(f));
  }
}

std::int64_t SurfaceQuery::CellOf(double mm) const {
  return static_cast<std::int64_t>(
      std::floor(std::clamp(mm / cell_mm_, -kMaxCellIndex, kMaxCellIndex)));
}

std::vector<int> SurfaceQuery::FacesIn(const Eigen::AlignedBox2d& box) const {
  std::vector<int> faces;
  if (!box.intersects(bounds_)) return faces;
  const auto meets = [&](int f) {
    Eigen::AlignedBox2d face_box;
    for (int k = 0; k < 3; ++k) face_box.extend(mesh_.positions[mesh_.faces[f][k]].head<2>());
    return face_box.intersects(box);
  };
  const Eigen::AlignedBox2d within = box.intersection(bounds_);
  const std::int64_t x0 = CellOf(within.min().x()), x1 = CellOf(within.max().x());
  const std::int64_t y0 = CellOf(within.min().y()), y1 = CellOf(within.max().y());
  const double spanned = static_cast<double>(x1 - x0 + 1) * static_cast<double>(y1 - y0 + 1);
  if (spanned > static_cast<double>(cells_.size())) {
    // A box larger than the occupied grid: walk the occupied cells instead.
    for (const auto& [key, cell] : cells_)
      for (int f : cell)
        if (meets(f)) faces.push_back(f);
  } else {
    for (std::int64_t y = y0; y <= y1; ++y)
      for (std::int64_t x = x0; x <= x1; ++x) {
        const auto cell = cells_.find(KeyOf(x, y));
        if (cell == cells_.end()) continue;
        for (int f : cell->second)
          if (meets(f)) faces.push_back(f);
      }
  }
  for (int f : large_faces_)
    if (meets(f)) faces.push_back(f);
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

double SurfaceQuery::VertexSigma(int v) const {
  return mesh_.uncertainty_mm.empty() ? 0.0 : static_cast<double>(mesh_.uncertainty_mm[v]);
}

Eigen::Vector3d SurfaceQuery::FaceNormal(int face) const {
  const Eigen::Vector3i& f = mesh_.faces[face];
  Eigen::Vector3d n = (mesh_.positions[f[1]] - mesh_.positions[f[0]])
                          .cross(mesh_.positions[f[2]] - mesh_.positions[f[0]]);
  if (n.z() < 0.0) n = -n;
  const double length = n.norm();
  return length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::UnitZ();
}

std::optional<SurfacePoint> SurfaceQuery::Above(const Eigen::Vector2d& xy) const {
  std::optional<SurfacePoint> best;
  for (int f : FacesIn(Eigen::AlignedBox2d(xy, xy))) {
    const Eigen::Vector3i& face = mesh_.faces[f];
    const Eigen::Vector3d& a = mesh_.positions[face[0]];
    const Eigen::Vector3d& b = mesh_.positions[face[1]];
    const Eigen::Vector3d& c = mesh_.positions[face[2]];
    const double det = (b - a).head<2>().x() * (c - a).head<2>().y() -
                       (c - a).head<2>().x() * (b - a).head<2>().y();
    if (std::abs(det) < 1e-12) continue;  // vertical face: the line runs along it
    const Eigen::Vector3d w = internal::Barycentric(a.head<2>(), b.head<2>(), c.head<2>(), xy);
    if (w.minCoeff() < -kInsideTolerance) continue;
    const Eigen::Vector3d p = w[0] * a + w[1] * b + w[2] * c;
    if (best && best->position.z() >= p.z()) continue;
    SurfacePoint point;
    point.position = Eigen::Vector3d(xy.x(), xy.y(), p.z());
    point.face = f;
    point.barycentric = w;
    double variance = 0.0;
    for (int k = 0; k < 3; ++k) variance += w[k] * w[k] * std::pow(VertexSigma(face[k]), 2);
    point.sigma_mm = std::sqrt(variance);
    best = point;
  }
  return best;
}

SurfacePoint SurfaceQuery::At(const Eigen::Vector2d& xy, const std::string& what) const {
  auto point = Above(xy);
  if (!point)
    throw MeasurementError(what + " (" + std::to_string(xy.x()) + ", " + std::to_string(xy.y()) +
                           ") mm is outside the surface");
  return *point;
}

std::vector<int> SurfaceQuery::VerticesNear(const Eigen::Vector2d& xy, double radius_mm) const {
  const Eigen::Vector2d r(radius_mm, radius_mm);
  std::vector<int> vertices;
  for (int f : FacesIn(Eigen::AlignedBox2d(xy - r, xy + r)))
    for (int k = 0; k < 3; ++k) {
      const int v = mesh_.faces[f][k];
      if ((mesh_.positions[v].head<2>() - xy).norm() <= radius_mm) vertices.push_back(v);
    }
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  return vertices;
}

double SurfaceQuery::InterpolationError(const SurfacePoint& point) const {
  const Eigen::Vector3i& face = mesh_.faces[point.face];
  double longest = 0.0;
  for (int k = 0; k < 3; ++k)
    longest = std::max(
        longest, (mesh_.positions[face[(k + 1) % 3]] - mesh_.positions[face[k]]).head<2>().norm());
  const Eigen::Vector2d centre = point.position.head<2>();
  const std::vector<int> near = VerticesNear(centre, kInterpolationNeighbourhood * longest);
  if (near.size() < 10) return 0.0;
  Eigen::MatrixXd a(near.size(), 6);
  Eigen::VectorXd z(near.size());
  for (std::size_t i = 0; i < near.size(); ++i) {
    const Eigen::Vector3d& p = mesh_.positions[near[i]];
    const double x = p.x() - centre.x(), y = p.y() - centre.y();
    a.row(i) << 1.0, x, y, x * x, x * y, y * y;
    z[i] = p.z();
  }
  const Eigen::VectorXd c = a.colPivHouseholderQr().solve(z);
  if (!c.allFinite()) return 0.0;
  return std::abs(c[0] - point.position.z());
}

}  // namespace bsls::measurement
