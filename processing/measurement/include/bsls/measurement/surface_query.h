// Where a vertical line meets a SurfaceMesh, and which faces and vertices lie
// near an x-y position: the look-ups every measurement starts from.
//
// Frame and units: world frame of contracts section 3, millimetres; x-y
// positions are world (x, y), "above" means towards +z (the cameras).
// Errors: MeasurementError (measurement_error.h) naming the input and reason.
// Ownership and thread-safety: SurfaceQuery borrows the mesh, which must
// outlive it and not change; const members may be called concurrently.
#ifndef BSLS_MEASUREMENT_SURFACE_QUERY_H_
#define BSLS_MEASUREMENT_SURFACE_QUERY_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "bsls/geometry/surface_mesh.h"
#include "bsls/measurement/measurement_error.h"

namespace bsls::measurement {

// A closed polygon in the world x-y plane (mm), either orientation, not
// self-intersecting; the last vertex connects back to the first.
using Polygon2d = std::vector<Eigen::Vector2d>;

// A point on the mesh surface.
struct SurfacePoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();     // world mm
  int face = -1;                                          // index into mesh.faces
  Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();  // weights of the face's vertices
  // 1-sigma uncertainty of position (mm, per axis): the vertices' uncertainty
  // interpolated (sqrt(sum b_i^2 s_i^2)); 0 when the mesh carries none.
  double sigma_mm = 0.0;
};

class SurfaceQuery {
 public:
  // Indexes the faces on an x-y grid of `cell_mm` (0: twice the median edge
  // length), kept sparse so that a vertex thrown far away (a damaged file)
  // costs neither memory nor the resolution of the rest; a face spanning more
  // than a few cells is kept aside and tested by every query. Throws
  // MeasurementError for an invalid mesh or one without faces.
  explicit SurfaceQuery(const geometry::SurfaceMesh& mesh, double cell_mm = 0.0);

  // The highest surface point on the vertical line through `xy`; nullopt
  // when the line meets no face.
  std::optional<SurfacePoint> Above(const Eigen::Vector2d& xy) const;
  // As Above(), but throws MeasurementError "<what> (x, y) is outside the surface".
  SurfacePoint At(const Eigen::Vector2d& xy, const std::string& what) const;
  // Faces whose x-y bounding box meets `box` (each once, ascending).
  std::vector<int> FacesIn(const Eigen::AlignedBox2d& box) const;
  // Vertices of faces within `radius_mm` (x-y distance) of `xy` (each once).
  std::vector<int> VerticesNear(const Eigen::Vector2d& xy, double radius_mm) const;
  // 1-sigma uncertainty of vertex `v` (mm); 0 when unknown.
  double VertexSigma(int v) const;
  // Unit normal of face `face`, on the +z side; +z for a degenerate face.
  Eigen::Vector3d FaceNormal(int face) const;
  // Estimated error (mm, >= 0) of linear interpolation at `point`: how far a
  // quadric fitted to the vertices around it lies from the face's plane.
  double InterpolationError(const SurfacePoint& point) const;

  const geometry::SurfaceMesh& mesh() const { return mesh_; }
  // Median edge length of the mesh (mm).
  double median_edge_mm() const { return median_edge_mm_; }

 private:
  const geometry::SurfaceMesh& mesh_;
  Eigen::AlignedBox2d bounds_;
  double cell_mm_ = 1.0;
  double median_edge_mm_ = 1.0;
  // The grid cell of a coordinate (clamped far outside any scan).
  std::int64_t CellOf(double mm) const;

  std::unordered_map<std::uint64_t, std::vector<int>> cells_;  // faces per occupied cell
  std::vector<int> large_faces_;  // faces spanning more cells than kMaxCellsPerFace
};

}  // namespace bsls::measurement

#endif  // BSLS_MEASUREMENT_SURFACE_QUERY_H_
