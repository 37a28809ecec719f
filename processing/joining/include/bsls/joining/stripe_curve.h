// One labelled stripe of a surface mesh (all vertices with the same p) as an
// ordered polyline, with the closest-point query the joining stage aligns on.
//
// Frame and units: whatever frame the mesh's positions are in, millimetres.
// Order: from the top of the face to the bottom (decreasing y of that frame);
// a stripe crosses each height once, as the projector's rays do (thesis 5.2).
// Samples further apart than a gap are not joined: the curve is a set of runs.
//
// Thread-safety: a value type; const methods may be called concurrently.
#ifndef BSLS_JOINING_STRIPE_CURVE_H_
#define BSLS_JOINING_STRIPE_CURVE_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "bsls/geometry/surface_mesh.h"

namespace bsls::joining {

// The point of a curve closest to a query point.
struct CurvePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();     // on the curve, mm
  Eigen::Vector3d tangent = Eigen::Vector3d::UnitY();  // unit, along the segment
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    // surface normal there (unit), zero: unknown
  double distance_mm = 0.0;                            // from the query point
};

class StripeCurve {
 public:
  StripeCurve() = default;
  // The vertices of `mesh` labelled `p`, ordered by decreasing y; neighbours
  // more than `max_gap_mm` apart start a new run. Normals are the mesh's, or
  // computed from its faces (area-weighted) when it has none, or unknown.
  // An empty curve when no vertex has that label (or `line` is empty).
  static StripeCurve FromMesh(const geometry::SurfaceMesh& mesh, int p, double max_gap_mm);

  std::size_t size() const { return points_.size(); }
  bool empty() const { return points_.empty(); }
  // Positions, top to bottom.
  const std::vector<Eigen::Vector3d>& points() const { return points_; }
  // Mesh vertex index of each point.
  const std::vector<int>& vertices() const { return vertices_; }
  // True when point i and point i+1 are joined by a segment.
  bool Joined(std::size_t i) const { return joined_[i] != 0; }

  // The closest point on a segment within `max_distance_mm` of `query`, or
  // nullopt when there is none or the closest point is an end of a run (the
  // query lies beyond the curve, where it has no partner).
  std::optional<CurvePoint> Closest(const Eigen::Vector3d& query, double max_distance_mm) const;

  // This curve moved by `transform` (points and normals).
  StripeCurve Transformed(const Eigen::Isometry3d& transform) const;

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<Eigen::Vector3d> normals_;  // empty: unknown
  std::vector<int> vertices_;
  std::vector<char> joined_;  // size() - 1 entries (0 when empty)
  // Spheres around runs of kChunk segments (chunk c: points c * kChunk ..
  // (c + 1) * kChunk), so that Closest skips the runs that cannot hold a
  // nearer point.
  static constexpr std::size_t kChunk = 16;
  struct Bound {
    Eigen::Vector3d centre;
    double radius;
  };
  std::vector<Bound> bounds_;
  void ComputeBounds();
};

// Unit vertex normals of `mesh`: its own when present, else area-weighted from
// its faces, else empty (a point cloud without normals).
std::vector<Eigen::Vector3d> VertexNormals(const geometry::SurfaceMesh& mesh);

}  // namespace bsls::joining

#endif  // BSLS_JOINING_STRIPE_CURVE_H_
