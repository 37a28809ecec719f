// Merging two sides already in one frame into one mesh, stitched along the
// reference line, and the seam error between them.
//
// Frame and units: both meshes in the same (the left side's) world frame,
// contracts section 3, millimetres.
#ifndef BSLS_JOINING_STITCH_H_
#define BSLS_JOINING_STITCH_H_

#include <cstddef>
#include <string>

#include "bsls/geometry/surface_mesh.h"
#include "bsls/joining/stripe_curve.h"

namespace bsls::joining {

struct StitchParams {
  // Zipper triangles with an edge longer than this are not made (mm, > 0): a
  // depth jump or a hole between the seam lines is left open. The rig's lines
  // are 5.7 mm apart at z = 0 and sampled every 0.5 mm.
  double max_edge_mm = 12.0;
  // Seam samples further than this from the other side's line are not
  // counted (mm, > 0): they have no partner there.
  double max_seam_distance_mm = 10.0;

  // True when the numbers are in range; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

struct StitchResult {
  // Left's vertices and faces first (all of them, unchanged), then right's
  // without its reference-line vertices, then the zipper faces. Attributes:
  // concatenated; normals or uncertainties when both sides have them; flags
  // filled with 0 for a side without. `line` keeps each side's own p, so the
  // side of a vertex is told by its index (below right_vertex_offset: left).
  geometry::SurfaceMesh mesh;
  std::size_t right_vertex_offset = 0;
  int zipper_triangles = 0;          // faces made across the seam
  int skipped_zipper_triangles = 0;  // not made: an edge over max_edge_mm or across a gap
};

// The seam error: every reference-line vertex of each side to the other's
// reference-line polyline (closest point across it).
struct SeamError {
  double rms_mm = 0.0;
  double max_mm = 0.0;
  int samples = 0;  // vertices with a partner within max_seam_distance_mm
};

// Left kept whole (its reference line is the seam; thesis 5.2.2 takes the
// left side as correct), right without its reference-line vertices and the
// faces on them; right's line reference+1 zipped to left's reference line
// (the shorter diagonal first). Both meshes must be valid and in one frame.
StitchResult StitchAlongReferenceLine(const geometry::SurfaceMesh& left,
                                      const geometry::SurfaceMesh& right, int reference_line,
                                      double max_line_gap_mm, const StitchParams& params);

// RMS and largest distance of each curve's points to the other curve.
SeamError MeasureSeam(const StripeCurve& left, const StripeCurve& right,
                      const StitchParams& params);

}  // namespace bsls::joining

#endif  // BSLS_JOINING_STITCH_H_
