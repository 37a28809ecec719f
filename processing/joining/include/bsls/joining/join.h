// Joining the left and right surfaces of a face into one mesh (thesis 5.2.2).
//
// Each side is reconstructed on its own and both carry the reference line
// (p = 0, the facial midline, contracts section 1), the curve they share.
//  - JoinSharedFrame: both sides were calibrated against the same target
//    positions (contracts section 4), so they share one world frame: merge
//    and stitch along the reference line, no matching.
//  - JoinByFeatures: the frames differ by a rigid motion (the rig set up
//    again for the other side): thesis 5.2.2's feature matching on the common
//    line (nose and mouth, turning points of its profile) gives the initial
//    transform of the right side onto the left, refined by ICP on the common
//    line (point-to-curve + point-to-plane, trimmed and Huber-weighted); then
//    merged as above. The left side is the reference (thesis: "considered to
//    be correct").
//
// Frames and units: each mesh in its side's world frame (contracts section 3),
// millimetres; the joined mesh and all reported points are in the left
// side's frame. The transform maps right to left: x_left = R x_right + t.
// Differences from the thesis: no scaling (both reconstructions are metric;
// the nose-to-mouth ratio is reported instead), and ICP refines the match.
//
// Errors: JoinError naming the side ("left mesh", "right mesh") or
// "parameters" and the reason. Thread-safety: pure functions.
#ifndef BSLS_JOINING_JOIN_H_
#define BSLS_JOINING_JOIN_H_

#include <Eigen/Core>
#include <string>

#include "bsls/common/cancellation.h"
#include "bsls/geometry/surface_mesh.h"
#include "bsls/joining/features.h"
#include "bsls/joining/icp.h"
#include "bsls/joining/join_error.h"
#include "bsls/joining/stitch.h"

namespace bsls::joining {

struct JoinParams {
  int reference_line = 0;        // p of the line both sides see (contracts 1), >= 0
  double max_line_gap_mm = 3.0;  // samples of a line further apart are not joined (> 0)
  FeatureParams features;        // JoinByFeatures only
  IcpParams icp;                 // JoinByFeatures only
  StitchParams stitch;

  // True when every field is in range; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

struct JoinResult {
  geometry::SurfaceMesh mesh;           // left frame; see StitchResult for the layout
  std::size_t right_vertex_offset = 0;  // first vertex that came from the right side
  // Right to left: x_left = rotation * x_right + translation (identity when shared).
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // mm
  // The feature match alone (before ICP), same convention.
  Eigen::Matrix3d initial_rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d initial_translation = Eigen::Vector3d::Zero();
  int iterations = 0;           // ICP steps (0 when shared)
  double icp_rms_mm = 0.0;      // RMS of ICP's trimmed point-to-curve pairs at the end
  SeamError seam;               // after joining, in the left frame
  LineFeatures left_features;   // empty when shared; in the left frame
  LineFeatures right_features;  // empty when shared; in the right side's own frame
  // Thesis 5.2.2 step 1's scale: left nose-to-mouth distance over right's (1 when shared).
  double feature_scale = 1.0;
  int zipper_triangles = 0;
  int skipped_zipper_triangles = 0;
};

// Both sides in one world frame: the merged, stitched mesh and the seam
// error. Throws JoinError for invalid params or meshes, an empty mesh, or a
// side without vertices on the reference line.
// `cancel` is asked between the steps (Cancelled when asked to stop).
JoinResult JoinSharedFrame(const geometry::SurfaceMesh& left, const geometry::SurfaceMesh& right,
                           const JoinParams& params, const Cancellation& cancel = {});

// Thesis 5.2.2: the right side matched onto the left by the nose and mouth
// of the common line, refined by ICP, then merged and stitched. Throws
// JoinError as JoinSharedFrame, and when a side's nose or mouth is not found
// (kFeaturesNotFound) or ICP does not converge (kNotConverged).
// `cancel` is asked between the steps and every ICP step.
JoinResult JoinByFeatures(const geometry::SurfaceMesh& left, const geometry::SurfaceMesh& right,
                          const JoinParams& params, const Cancellation& cancel = {});

}  // namespace bsls::joining

#endif  // BSLS_JOINING_JOIN_H_
