// Rigid registration of a surface onto an earlier scan of the same face (its
// baseline): the step that lets a lesion be measured against the face as it
// was, not against a surface guessed from a ring around it.
//
// Method: point-to-plane iterative closest points, robust (Huber weights,
// pairs beyond 4 robust sigmas left out as changes of the face),
// over the vertices of the surface OUTSIDE an excluded region (the lesion):
// each vertex is paired with the baseline point straight below or above it
// (SurfaceQuery::Above) and the distance to that baseline face's plane is
// minimised over rotations and translations by Gauss-Newton steps about the
// points' centroid. Small motions between two sessions (a patient repositioned
// by a few millimetres and degrees) are what it is for; it starts from the
// identity.
//
// Frame and units: both surfaces in the world frame of contracts section 3
// (their own sessions), millimetres; the result maps the surface's frame to
// the baseline's.
// Errors: MeasurementError naming the input and the reason (too few pairs,
// a surface that does not fix a rigid motion, no convergence).
#ifndef BSLS_MEASUREMENT_BASELINE_REGISTRATION_H_
#define BSLS_MEASUREMENT_BASELINE_REGISTRATION_H_

#include <Eigen/Geometry>
#include <string>

#include "bsls/measurement/surface_query.h"

namespace bsls::measurement {

struct BaselineParams {
  bool register_rigidly = true;            // false: the two scans share one frame as they are
  double max_pair_mm = 5.0;                // pairs further apart (plane distance) are ignored, > 0
  double huber_mm = 0.3;                   // Huber threshold on the plane distance, > 0
  int max_iterations = 50;                 // Gauss-Newton steps, >= 1
  double converged_rotation_deg = 1e-3;    // a step below this rotation ...
  double converged_translation_mm = 1e-3;  // ... and translation ends the iteration (> 0)
  int max_points = 20000;                  // vertices used (evenly thinned), >= 100
  int min_pairs = 100;                     // fewer pairs is an error, >= 6
  // Share of the lesion region's surface the baseline must lie under, (0, 1];
  // where it does not, the region's area and volume are not measured.
  double min_coverage = 0.8;

  // True when the numbers are in range; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

struct BaselineRegistration {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  // surface frame -> baseline frame
  bool rigid = true;    // false: the identity was kept (BaselineParams::register_rigidly)
  int iterations = 0;   // Gauss-Newton steps taken
  int pairs = 0;        // inlier vertex-plane pairs at the end
  double rms_mm = 0.0;  // RMS plane distance of those pairs (both scans' noise, resampling)
};

// The rigid motion taking `surface` onto `baseline`, fitted on the vertices
// of `surface` outside `exclude` (world x-y polygon; may be empty: every
// vertex). With params.register_rigidly false, the identity and its pairs'
// RMS. Throws MeasurementError for invalid params, fewer than min_pairs pairs,
// a degenerate overlap (a plane or a cylinder does not fix all six degrees of
// freedom) or no convergence within max_iterations.
BaselineRegistration RegisterToBaseline(const SurfaceQuery& surface, const SurfaceQuery& baseline,
                                        const Polygon2d& exclude, const BaselineParams& params);

}  // namespace bsls::measurement

#endif  // BSLS_MEASUREMENT_BASELINE_REGISTRATION_H_
