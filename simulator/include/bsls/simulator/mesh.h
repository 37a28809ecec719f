// Triangle meshes: loaders (Wavefront OBJ, JSON positions/cells), Loop
// subdivision, and a surface that intersects rays through a bounding-volume
// hierarchy (median split).
//
// Units: whatever the file holds; callers scale to millimetres (the face OBJ is
// in centimetres, see scene.h). Triangles are counter-clockwise seen from their
// front side (outside).
//
// Errors: every loader throws MeshLoadError, whose what() names the file and
// the reason ("<path>: line 12: face refers to vertex 900 of 468"). Nothing
// else in this header throws for bad file content.
//
// Thread-safety: MeshSurface is immutable after construction; Intersect() may
// be called concurrently.
#ifndef BSLS_SIMULATOR_MESH_H_
#define BSLS_SIMULATOR_MESH_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "bsls/simulator/surface.h"

namespace bsls::simulator {

// A mesh file that cannot be read: missing, unreadable or malformed.
class MeshLoadError : public std::runtime_error {
 public:
  // what() is "<path>: <reason>".
  MeshLoadError(const std::filesystem::path& path, const std::string& reason);

  // The file that could not be read.
  const std::filesystem::path& path() const { return path_; }
  // Why, without the file name.
  const std::string& reason() const { return reason_; }

 private:
  std::filesystem::path path_;
  std::string reason_;
};

// Vertices and triangles (indices into vertices, 0-based).
struct IndexedMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;

  // True when there is at least one triangle, every index is in range, every
  // vertex is finite and no triangle repeats a vertex; otherwise says why.
  bool IsValid(std::string* error) const;
  // Axis-aligned bounds of the vertices (empty box for an empty mesh).
  Eigen::AlignedBox3d Bounds() const;
};

// Reads the vertices ("v") and faces ("f", polygons fan-triangulated; "i",
// "i/j", "i//k", "i/j/k" and negative indices accepted) of a Wavefront OBJ.
// Throws MeshLoadError when the file is missing or malformed.
IndexedMesh LoadObj(const std::filesystem::path& path);

// Reads a JSON mesh {"positions": [[x, y, z], ...], "cells": [[i, j, k], ...]}
// (0-based indices, as the npm `bunny` package). Throws MeshLoadError.
IndexedMesh LoadMeshJson(const std::filesystem::path& path);

// `levels` rounds of Loop subdivision (Loop 1987; boundary edges use the
// cubic B-spline rule, non-manifold edges are kept as creases). Each level
// multiplies the triangle count by 4. `mesh` must be valid.
IndexedMesh LoopSubdivide(const IndexedMesh& mesh, int levels);

// Area-weighted vertex normals (unit; zero for unused vertices).
std::vector<Eigen::Vector3d> VertexNormals(const IndexedMesh& mesh);

// `mesh` with every vertex mapped through `transform` (triangle winding kept;
// pass a proper rotation, or mirror the winding yourself).
IndexedMesh Transformed(const IndexedMesh& mesh, const Eigen::Affine3d& transform);

// A triangle mesh surface with smooth (interpolated vertex) shading normals.
class MeshSurface final : public Surface {
 public:
  // Builds the BVH. Throws std::invalid_argument when `mesh` is not valid.
  MeshSurface(IndexedMesh mesh, std::string name);

  // Nearest hit through the BVH, both sides of every triangle.
  std::optional<Hit> Intersect(const geometry::Ray& ray, double max_distance) const override;
  // The same answer by testing every triangle; the reference for the BVH.
  std::optional<Hit> IntersectBruteForce(const geometry::Ray& ray, double max_distance) const;
  // The name given at construction.
  std::string Name() const override { return name_; }

  // The triangles as given at construction.
  const IndexedMesh& mesh() const { return mesh_; }
  // Number of BVH nodes (for tests and reports).
  int bvh_node_count() const { return static_cast<int>(nodes_.size()); }

 private:
  struct Node {
    double lo[3];
    double hi[3];
    int first_or_right = 0;  // leaf: first triangle slot; interior: right child index
    int count = 0;           // leaf: number of triangles; interior: 0
    int axis = 0;            // interior: split axis
  };
  struct Triangle {
    Eigen::Vector3d v0, e1, e2;  // v1 = v0 + e1, v2 = v0 + e2
    int index = 0;               // into mesh_.triangles
  };
  // Möller-Trumbore; on a hit closer than *best updates *best, *u, *v.
  static bool HitTriangle(const Triangle& tri, const geometry::Ray& ray, double* best, double* u,
                          double* v);
  int Build(std::vector<int>& order, int begin, int end, int depth);
  Hit MakeHit(const geometry::Ray& ray, int slot, double t, double u, double v) const;

  IndexedMesh mesh_;
  std::string name_;
  std::vector<Eigen::Vector3d> vertex_normals_;
  std::vector<Triangle> triangles_;  // in BVH leaf order
  std::vector<Node> nodes_;          // depth-first; left child of node i is i + 1
};

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_MESH_H_
