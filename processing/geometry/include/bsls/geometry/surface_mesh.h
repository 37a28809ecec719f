// A reconstructed surface: vertices in world millimetres with per-vertex
// attributes, and triangles (none for a point cloud). Shared by the
// reconstruction stage that builds it, the surface files that store it, the
// joining of two sides and the measurements taken on it.
//
// Frames and units: world frame of contracts section 3, millimetres (x right,
// y up, z towards the cameras; z = 0 is the base plane).
// Faces: three vertex indices, counter-clockwise seen from the side the
// surface faces (towards the cameras: its normals point to +z mostly).
// Attributes: every non-empty attribute vector has one entry per vertex; an
// empty one means "not known" (e.g. a mesh read from a file without it).
//
// Thread-safety: a value type; no shared state.
#ifndef BSLS_GEOMETRY_SURFACE_MESH_H_
#define BSLS_GEOMETRY_SURFACE_MESH_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace bsls::geometry {

// Bits of SurfaceMesh::flags.
enum VertexFlag : std::uint8_t {
  kVertexJunction = 1u << 0,  // a labelled junction, not a line sample
  kVertexBridged = 1u << 1,   // interpolated across a gap (B-spline), not measured
  kVertexSmoothed = 1u << 2,  // moved by along-line smoothing
};

struct SurfaceMesh {
  std::vector<Eigen::Vector3d> positions;  // world mm
  std::vector<Eigen::Vector3d> normals;    // unit length; empty: not computed
  std::vector<float> uncertainty_mm;       // 1-sigma position uncertainty; empty: unknown
  std::vector<std::int32_t> line;          // p label of the stripe it lies on; empty: unknown
  std::vector<std::uint8_t> flags;         // VertexFlag bits; empty: all clear
  std::vector<Eigen::Vector3i> faces;      // vertex indices; empty: a point cloud

  std::size_t VertexCount() const { return positions.size(); }
  // True when the attribute sizes match positions, every face index is in
  // range and no face repeats a vertex; otherwise names the part and why.
  bool IsValid(std::string* error) const;
};

}  // namespace bsls::geometry

#endif  // BSLS_GEOMETRY_SURFACE_MESH_H_
