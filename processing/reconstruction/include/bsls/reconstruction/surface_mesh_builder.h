// The polygon mesh of one side (thesis 5.2.1): triangles between the
// triangulated samples of neighbouring labelled lines p and p + 1, paired by
// image row or stitched (StripMethod), with Gouraud vertex normals (thesis
// 5.2.1, [114]).
//
// Frames and units: world millimetres (contracts section 3); rows are image
// rows of the camera (pixels). Faces are counter-clockwise seen from the
// camera centre, so normals point towards the camera (+z mostly).
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_RECONSTRUCTION_SURFACE_MESH_BUILDER_H_
#define BSLS_RECONSTRUCTION_SURFACE_MESH_BUILDER_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "bsls/geometry/surface_mesh.h"

namespace bsls::reconstruction {

// One triangulated sample of a line.
struct LineVertex {
  int row = 0;  // image row of the sample (the decoder's one centre per row)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world mm
  float sigma_mm = 0.0f;                               // 1-sigma position uncertainty
  std::uint8_t flags = 0;                              // geometry::VertexFlag bits
};

// The samples of labelled line p, by strictly increasing row; missing rows
// are gaps (shadows, occlusions, unrepaired breaks).
struct TriangulatedLine {
  int p = 0;
  std::vector<LineVertex> vertices;
};

// How the triangles of a strip between lines p and p + 1 are chosen.
enum class StripMethod {
  // Thesis 5.2.1: the samples of the same image row paired, quad by quad.
  // Where the lines lean the quads shear, and a strip ends at the row where
  // the first of its two lines ends.
  kRowPairs,
  // Each strip stitched (Christiansen and Sederberg 1978): the next triangle
  // takes the next sample of whichever line makes the new edge between the
  // lines shorter, so the triangles join the samples that face each other
  // and a strip reaches as far as its lines do. The default: measured
  // against row pairs in docs/reconstruction.md ("Stitched strips").
  kStitched,
};

struct MeshParams {
  StripMethod strips = StripMethod::kStitched;
  // A triangle edge between lines p and p + 1 longer than this many times the
  // local spacing spans a depth jump or a shadow: the triangle is dropped.
  // Local spacing: over the strips p-2 .. p+2, the median row-aligned edge
  // between neighbouring lines (kRowPairs) or the median distance from a
  // sample to the nearest of the other line (kStitched): ~ the projected
  // line pitch, growing where the light meets the surface obliquely.
  double max_across_ratio = 3.0;
  // An edge along a line (consecutive rows) longer than this many times the
  // line's median step, and longer than min_along_jump_mm, is a depth jump:
  // no triangle uses it. Steep surfaces have long steps; the ratio leaves room.
  double max_along_ratio = 6.0;
  double min_along_jump_mm = 1.0;
  // kStitched: an edge between the lines longer than this many times the
  // distance from either of its ends to the nearest sample of the other
  // line fans out from a line's end (the other line ended or bends away):
  // no triangle uses it. >= 1.
  double max_stitch_ratio = 1.5;

  // True when the numbers are usable; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

// What BuildSurfaceMesh did.
struct MeshReport {
  int vertices = 0;
  int triangles = 0;
  int dropped_across = 0;  // triangles refused for a too long edge between lines
  int dropped_along = 0;   // quads (kStitched: steps) refused for a depth jump or gap along a line
};

// Thesis 5.2.1: triangles between each pair of neighbouring lines p, p + 1.
// kRowPairs: for each row y where both lines have samples at y and y + 1 (a
// gap on either line, i.e. a missing row, leaves a hole), the quad of those
// four samples split along its shorter diagonal into two triangles.
// kStitched: the strip stitched from the lines' first samples to their last;
// a step across a gap makes no triangle. Either way no triangle with an edge
// too long (MeshParams). Vertices are every sample of every line in
// the order given (line by line), their attributes copied (line = p);
// normals are the average of the unit normals of the faces around each
// vertex (Gouraud), or the unit vector towards the camera for a vertex in no
// face. Faces are wound counter-clockwise seen from `camera_centre`.
// Throws std::invalid_argument for invalid params or lines whose rows are not
// strictly increasing.
geometry::SurfaceMesh BuildSurfaceMesh(const std::vector<TriangulatedLine>& lines,
                                       const Eigen::Vector3d& camera_centre,
                                       const MeshParams& params = {}, MeshReport* report = nullptr);

}  // namespace bsls::reconstruction

#endif  // BSLS_RECONSTRUCTION_SURFACE_MESH_BUILDER_H_
