// Three-dimensional reconstruction of one side (thesis 5.2): the labelled
// lines and junctions of a decode triangulated (triangulation.h), short gaps
// on a line bridged by cubic B-splines (thesis Appendix B), optional
// along-line smoothing (thesis eq. 5.32), and the polygon mesh between
// neighbouring lines (thesis 5.2.1, surface_mesh_builder.h) in one call.
//
// Frames and units: image pixels in (DecodeResult), world millimetres out
// (contracts section 3); SurfaceMesh attributes as in
// bsls/geometry/surface_mesh.h.
//
// Vertices of the result, in order: the samples of every line by increasing
// p, each line by increasing image row (measured and bridged samples), then
// the junctions (ReconstructionParams::include_junctions) by p then q. The
// junctions are kept as flagged vertices (kVertexJunction) that no face uses:
// the line samples already sample the surface once per row along each line,
// and a junction is an independent measurement (eq. 2.18 with a projector)
// for checks, joining and landmarks.
//
// Thread-safety: Reconstruct is a pure function of its arguments.
#ifndef BSLS_RECONSTRUCTION_RECONSTRUCTION_H_
#define BSLS_RECONSTRUCTION_RECONSTRUCTION_H_

#include <stdexcept>
#include <string>

#include "bsls/decoder/decoder.h"
#include "bsls/geometry/surface_mesh.h"
#include "bsls/reconstruction/surface_mesh_builder.h"
#include "bsls/reconstruction/triangulation.h"

namespace bsls::reconstruction {

// A decode that cannot be reconstructed (nothing labelled, wrong side, no
// sample on any light plane); what() names the input and the reason.
class ReconstructionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ReconstructionParams {
  MeshParams mesh;
  // Thesis eq. 5.32: x_i <- (x_i-1 + 6 x_i + x_i+1) / 8 on the stripe centres
  // along each run of consecutive rows (ends kept), before triangulation.
  // Off by default: it also flattens small real detail (thesis 5.2.1).
  bool smooth_lines = false;
  // Gaps of at most this many missing rows on a line are bridged by a cubic
  // B-spline through the stripe centres around them (thesis Appendix B);
  // 0 disables bridging. Longer gaps stay holes in the mesh.
  int max_bridge_rows = 6;
  // A longer gap that holds a junction of the line is bridged up to this
  // many missing rows (0: never): the junction lies on the line, and the
  // decoder leaves out the rows beside a steep line's segment, so the gap
  // is pinned in its middle. Each stretch between the gap's ends and its
  // junctions is a cubic Hermite curve x(row) with Catmull-Rom tangents.
  int max_anchored_bridge_rows = 24;
  // px: a junction farther than this from the Hermite curve across its gap
  // without it does not pin the gap (a fold or a misplaced junction): no bridge.
  double max_anchor_offset_px = 3.0;
  // px: image error of a bridged centre, added in quadrature to the stripe
  // centre's along the row (bridged vertices are interpolated, not measured).
  double bridge_sigma_px = 0.5;
  // Also add the junctions as flagged vertices (see above).
  bool include_junctions = true;

  // True when the numbers are usable; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

// What Reconstruct did.
struct ReconstructionReport {
  int vertices = 0;                // in the mesh, junctions included
  int measured_samples = 0;        // line samples triangulated from the decode
  int bridged_samples = 0;         // added across short gaps
  int smoothed_samples = 0;        // moved by eq. 5.32
  int dropped_samples = 0;         // line samples with no light plane or no intersection
  int junctions = 0;               // junction vertices
  int dropped_junctions = 0;       // junctions that could not be triangulated
  int junctions_by_projector = 0;  // of `junctions`, by eq. 2.18
  int triangles = 0;
  int dropped_triangles = 0;  // refused across a depth jump or shadow (MeshReport)
  double time_ms = 0.0;       // wall time of Reconstruct
};

// Decode in, mesh out (thesis 5.2). Throws ReconstructionError when the
// decode failed, holds no labelled line sample, is of the other side than the
// model, or no sample meets a light plane; std::invalid_argument for an
// invalid model or params.
geometry::SurfaceMesh Reconstruct(const decoder::DecodeResult& decode,
                                  const TriangulationModel& model,
                                  const ReconstructionParams& params = {},
                                  ReconstructionReport* report = nullptr);

// The same with a Triangulator already built from the model (saves building
// it again per frame).
geometry::SurfaceMesh Reconstruct(const decoder::DecodeResult& decode,
                                  const Triangulator& triangulator,
                                  const ReconstructionParams& params = {},
                                  ReconstructionReport* report = nullptr);

}  // namespace bsls::reconstruction

#endif  // BSLS_RECONSTRUCTION_RECONSTRUCTION_H_
