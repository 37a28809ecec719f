// Projector calibration (thesis 6.2): models of the light planes of the
// vertical lines fitted to 3-D points measured on them, and the projector's
// 3x4 matrix (thesis 2.3, eq. 2.16) fitted to junctions.
//
//   (a) FitParallelPlaneModel      thesis 6.2.1, eq. 6.1-6.2: n.r = d0 (e - e0).
//   (b) FitPerspectivePlaneModel   thesis 6.2.2, eq. 6.3-6.6:
//                                  (r - P0).(n0 + e p) = 0.
//   (c) FitProjectorMatrix         thesis eq. 2.16 by the linear solution of
//                                  eq. 2.19, refined (Levenberg-Marquardt) to a
//                                  geometry::PinholeModel in slide units.
// (a) and (b) use the thesis's two-pass outlier rejection: fit all points,
// drop those further than k sigma from the fit, fit again.
//
// Frames and units:
//   world   millimetres, contracts section 3 (x right, y up, z towards the
//           cameras and projector). Points are typically camera detections
//           back-projected onto screens at known z (thesis 6.2).
//   e       the line index of a light plane: the p label of contracts
//           section 2 (0 = reference line); any integer, also negative.
//   slide   (s, t) in line pitches d, bsls/pattern/brick_pattern.h; the
//           junction (p, q) of a side sits at (SFromU(side, p), q).
//
// Errors: CalibrationError (calibration_error.h); never an assert on input.
// Thread-safety: pure functions of their arguments; the result types are values.
#ifndef BSLS_CALIBRATION_PROJECTOR_CALIBRATION_H_
#define BSLS_CALIBRATION_PROJECTOR_CALIBRATION_H_

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "bsls/calibration/calibration_error.h"
#include "bsls/calibration/camera_calibration.h"
#include "bsls/geometry/pinhole_model.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::calibration {

// The plane normal . r = offset_mm in world mm; normal has unit length.
struct LightPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  double offset_mm = 0.0;

  // Signed distance (mm) of a world point, positive on the normal's side.
  double SignedDistance(const Eigen::Vector3d& point) const {
    return normal.dot(point) - offset_mm;
  }
  // Where a ray meets the plane (ray/plane triangulation, thesis 2.3); nullopt
  // when the ray is parallel to the plane or meets it behind its origin.
  std::optional<Eigen::Vector3d> Intersect(const geometry::Ray& ray) const;
};

// A world point measured on the light plane of line e.
struct StripePoint {
  Eigen::Vector3d world_mm = Eigen::Vector3d::Zero();
  int line = 0;  // e
};

// Two-pass outlier rejection of (a) and (b) (thesis 6.2.1).
struct StripeFitParams {
  // A point further from its fitted plane than outlier_sigma times the RMS
  // distance (over the kept points) of the previous fit is dropped before
  // refitting; every input point is judged again against each fit. <= 0
  // disables rejection. One round only drops outliers beyond k sigma of the
  // first fit, whose sigma the outliers themselves inflate.
  double outlier_sigma = 3.0;
  int rejection_rounds = 1;  // refits after dropping; thesis: 1 (two passes in all)
  // mm: points closer to the fit than this are never dropped, however small
  // sigma is (noise-free data would otherwise lose points to rounding).
  double min_outlier_distance_mm = 1e-3;

  // True when the numbers are usable; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

// What a stripe fit achieved, over the points kept by the last pass.
struct StripeFitReport {
  int points_used = 0;
  int points_dropped = 0;
  double rms_mm = 0.0;  // RMS point-to-plane distance
  double max_mm = 0.0;
  double first_pass_rms_mm = 0.0;  // before any point was dropped
  std::vector<bool> inlier;        // per input point: kept by the last pass
};

// Thesis 6.2.1: parallel light planes n.r = d0 (e - e0).
struct ParallelPlaneModel {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  // unit, towards increasing e
  double spacing_mm = 1.0;                            // d0 > 0
  double e0 = 0.0;  // index (fractional) of the plane through the world origin

  // The plane of line e (any real e).
  LightPlane PlaneOfLine(double e) const;
};

struct ParallelPlaneFit {
  ParallelPlaneModel model;
  StripeFitReport report;
};

// Thesis 6.2.1, eq. 6.1-6.2, by linear least squares on e = (n / d0).r + e0.
// Needs >= 4 points on >= 2 lines not all in one plane; throws
// CalibrationError otherwise.
ParallelPlaneFit FitParallelPlaneModel(const std::vector<StripePoint>& points,
                                       const StripeFitParams& params = {});

// Thesis 6.2.2: a pencil of planes (r - P0).(n0 + e p) = 0 through the
// projector's centre.
struct PerspectivePlaneModel {
  // Normal of line 0 and its change per line, with the gauge component
  // gauge_axis of n0 equal to 1 (thesis: n_y = 1; see FitPerspectivePlaneModel).
  Eigen::Vector3d n0 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  // P0: the point of the pencil's axis with coordinate centre_axis equal to 0
  // (thesis: x0 = 0). Every plane contains the whole axis, so the stripes
  // cannot say where on it the projector lies; this is the spare degree of
  // freedom of thesis 6.2.2.
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_direction = Eigen::Vector3d::UnitY();  // unit, along n0 x p
  int gauge_axis = 0;                                         // 0 = x, 1 = y, 2 = z
  int centre_axis = 1;                                        // 0 = x, 1 = y, 2 = z

  // The plane of line e (any real e): normal n0 + e p normalised (its
  // gauge_axis component positive), through P0.
  LightPlane PlaneOfLine(double e) const;
  // The line e (fractional) whose normal is perpendicular to p: the plane
  // that contains the projector's optical axis (thesis: e = -(p.n0)/|p|^2).
  double CentralLine() const;
};

struct PerspectivePlaneFit {
  PerspectivePlaneModel model;
  StripeFitReport report;
  double centre_to_origin_mm = 0.0;  // |P0| (thesis Table 6.2, projector-to-origin distance)
  double axis_to_origin_mm = 0.0;    // distance from the world origin to the pencil's axis
};

// Thesis 6.2.2, eq. 6.3-6.6: the linear least-squares problem A X = B with
// X = (n0_a, n0_b, p_x, p_y, p_z, -P0.n0, -P0.p), one row per point
// r.(n0 + e p) - P0.n0 - e P0.p = 0 with n0 fixed to 1 in its gauge component.
// The thesis fixes n_y = 1 and x0 = 0, which suits horizontal stripes; here
// the gauge component is the largest of the normal (x for the vertical lines
// of contracts section 1) and P0 is fixed by zeroing the largest component
// of the axis direction (y for vertical lines). From the second pass on rows
// are weighted by 1 / |n_e| so that residuals are point-to-plane distances.
// Needs >= 8 points on >= 3 lines, not all in one plane; throws
// CalibrationError otherwise, and when the planes are parallel (no finite
// centre: use the parallel-plane model).
PerspectivePlaneFit FitPerspectivePlaneModel(const std::vector<StripePoint>& points,
                                             const StripeFitParams& params = {});

// A junction measured in the world and its place on the slide.
struct JunctionPoint {
  Eigen::Vector3d world_mm = Eigen::Vector3d::Zero();
  Eigen::Vector2d slide_st = Eigen::Vector2d::Zero();  // d; see SlideOfJunction
};

// Slide coordinates (s, t) of junction (p, q) on a side's brick slide:
// (SFromU(side, p), q). q must be the slide row (contracts section 2: q from
// a decode is only known up to an even offset unless the calibration fixes it).
Eigen::Vector2d SlideOfJunction(pattern::Side side, int p, int q);

struct ProjectorMatrixParams {
  bool refine_principal_point = true;  // else kept at the DLT's
  bool refine_k1 = true;
  bool refine_k2 = false;  // long-focus projector: one term is plenty (thesis 6.3)
  // Junctions whose reprojection error exceeds outlier_sigma times the RMS of
  // the previous fit are dropped before refitting; <= 0 disables.
  double outlier_sigma = 3.0;
  int rejection_rounds = 1;
  double min_outlier_distance_d = 1e-4;  // never drop junctions closer than this (d)
  int max_iterations = 200;

  // True when the numbers are usable; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

struct ProjectorMatrixReport {
  int points_used = 0;
  int points_dropped = 0;
  double rms_d = 0.0;  // RMS 2-D reprojection error on the slide, line pitches
  double max_d = 0.0;
  double residual_sigma_d = 0.0;  // per axis, sqrt(SSR / (2N - free parameters))
  DltSolution dlt;                // the linear eq. 2.16 / 2.19 solution, slide units
  std::vector<bool> inlier;       // per input junction: kept by the last pass
  int iterations = 0;
  bool converged = false;
};

struct ProjectorMatrixFit {
  geometry::PinholeModel model;  // slide units d, our distortion convention
  // K [R | t] of the refined model (distortion left out), slide units; the
  // matrix P of thesis eq. 2.16, scaled so that |P(2, 0..2)| = 1.
  Matrix34d matrix = Matrix34d::Zero();
  ProjectorMatrixReport report;
};

// Thesis 2.3 eq. 2.16 (linear solution as eq. 2.19) refined to a pinhole
// model with the two-pass outlier rejection. Needs >= 12 junctions not all in
// one plane; throws CalibrationError otherwise.
ProjectorMatrixFit FitProjectorMatrix(const std::vector<JunctionPoint>& junctions,
                                      const ProjectorMatrixParams& params = {});

// The light plane of slide column s of a projector model: the plane through
// its centre containing the rays of slide points (s, -t_half_extent) and
// (s, +t_half_extent), normal towards increasing s. Exact for an undistorted projector; with
// distortion the column is curved and this is its chord plane. Throws CalibrationError when the two
// rays coincide (t_half_extent <= 0).
LightPlane LightPlaneOfSlideColumn(const geometry::PinholeModel& projector, double s,
                                   double t_half_extent = 24.0);

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_PROJECTOR_CALIBRATION_H_
