// Rigid alignment of one side's common line onto the other's: iterative
// closest points with a point-to-curve term (distance to the other side's
// polyline, across it: pins x, which the midline's normals cannot) and a
// point-to-plane term (along the other side's surface normal there), robust
// (trimmed, then Huber-weighted), solved by Gauss-Newton steps with Eigen.
//
// Frames and units: `fixed` in the target frame, `moving` in the source
// frame; the result maps source to target: x_target = transform * x_source.
// Millimetres, radians inside, degrees in parameters where named so.
#ifndef BSLS_JOINING_ICP_H_
#define BSLS_JOINING_ICP_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "bsls/common/cancellation.h"
#include "bsls/joining/stripe_curve.h"

namespace bsls::joining {

struct IcpParams {
  int max_iterations = 60;                 // cap; not converged by then is an error (>= 1)
  double converged_rotation_deg = 1e-4;    // stop when one step rotates less than this (> 0)
  double converged_translation_mm = 1e-4;  // and translates less than this (> 0)
  double max_correspondence_mm = 10.0;     // pairs further apart are ignored (> 0)
  double trim_fraction = 0.1;              // worst pairs dropped each iteration, [0, 0.5)
  double huber_mm = 0.5;                   // Huber threshold on a pair's distance (> 0)
  double curve_weight = 1.0;               // point-to-curve term (>= 0)
  double plane_weight = 1.0;               // point-to-plane term (>= 0; needs normals)
  int min_correspondences = 20;            // fewer pairs is a failure (>= 6)

  // True when the numbers are in range; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

struct IcpResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // source -> target
  int iterations = 0;                                           // Gauss-Newton steps taken
  bool converged = false;   // the last step was below both thresholds
  int correspondences = 0;  // pairs used in the last step (after trimming)
  double rms_mm = 0.0;      // RMS point-to-curve distance of those pairs
  std::string failure;      // why it did not converge (empty when it did)
};

// Minimises, over rigid transforms T starting from `initial`, the robust sum
// of curve_weight * |P (T m - c)|^2 + plane_weight * (n . (T m - c))^2 over
// the points m of `moving`, c the closest point of `fixed` (P removes the
// component along the curve, n its surface normal). Does not throw: a
// failure (too few pairs, a degenerate system, the cap reached) comes back
// with converged = false and `failure` saying why. `params` must be valid.
// `cancel` is asked before every step (Cancelled when asked to stop).
IcpResult AlignToCurve(const StripeCurve& fixed, const std::vector<Eigen::Vector3d>& moving,
                       const Eigen::Isometry3d& initial, const IcpParams& params,
                       const Cancellation& cancel = {});

// Least-squares rigid transform (Kabsch) taking `source[i]` onto
// `target[i]`; at least 3 non-collinear pairs, else nullopt.
std::optional<Eigen::Isometry3d> RigidFromPairs(const std::vector<Eigen::Vector3d>& source,
                                                const std::vector<Eigen::Vector3d>& target);

}  // namespace bsls::joining

#endif  // BSLS_JOINING_ICP_H_
