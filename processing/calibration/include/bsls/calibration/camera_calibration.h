// Camera calibration from a calibration target moved along z (thesis 6.1;
// linear 11-parameter matrix of thesis 2.3, eq. 2.14-2.15 and 2.19; Tsai's
// two-stage method, Tsai 1987, non-coplanar variant).
//
// Stages:
//   1. SolveDlt: the 3x4 camera matrix C by the linear solution of eq. 2.19
//      (c34 = 1) on normalised data, and its decomposition C ~ K [R | t].
//   2. SolveTsaiLinear: Tsai's radial alignment constraint (RAC) gives R, tx,
//      ty and the uncertainty scale factor sx linearly for a known principal
//      point; then f and tz linearly (distortion taken as 0).
//   3. CalibrateCamera: both of the above, then Levenberg-Marquardt on f, sx,
//      (cx, cy), k1, k2, R, t minimising the reprojection error in pixels.
//
// Frames and units (contracts section 3, bsls/geometry/pinhole_model.h):
//   world   millimetres; target square (r, c) of a view at offset z_mm is at
//           (c * pitch, -r * pitch, z_mm).
//   image   pixels, x = column, y = row, origin at the centre of the top-left
//           pixel.
//   device  x right, y down, z along the view; X_dev = R X_world + t.
// Camera model: fx = sx * f, fy = f (pixels); distortion in our convention,
// ideal normalised (x, y) -> distorted (x, y)(1 + k1 r^2 + k2 r^4). Tsai's
// paper uses the inverse direction (distorted -> ideal); the RAC stage does
// not depend on it and the refinement works in ours throughout.
//
// Errors: CalibrationError (calibration_error.h) for invalid params, invalid
// input, too few points, coplanar points or a degenerate solve; never an
// assert on input.
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_CALIBRATION_CAMERA_CALIBRATION_H_
#define BSLS_CALIBRATION_CAMERA_CALIBRATION_H_

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "bsls/calibration/calibration_error.h"
#include "bsls/geometry/pinhole_model.h"

namespace bsls::calibration {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

// One detected target point: where it is and where the camera saw it.
struct TargetPoint {
  Eigen::Vector3d world_mm = Eigen::Vector3d::Zero();
  Eigen::Vector2d image_px = Eigen::Vector2d::Zero();
};

// The points seen at one target position (contracts section 4, camera_views).
// A view's points need not be coplanar; the errors in mm are measured on the
// plane z = world_mm.z() of each point.
struct TargetView {
  std::vector<TargetPoint> points;
};

// Fewest correspondences any stage accepts: the DLT has 11 unknowns, the RAC
// 7, the refinement up to 12; 12 points leave some redundancy for all.
inline constexpr int kMinCalibrationPoints = 12;

struct CameraCalibrationParams {
  // Principal point (px) used by the RAC and, when not refined, kept. Unset:
  // the image centre ((width - 1) / 2, (height - 1) / 2). The thesis measured
  // it optically (Lenz and Tsai's laser method) before calibrating.
  std::optional<Eigen::Vector2d> principal_point_px;
  bool refine_principal_point = false;  // also free in the refinement
  bool refine_scale_factor = true;      // sx free (else 1: square pixels)
  bool refine_k1 = true;
  bool refine_k2 = true;
  // RMS distance (mm) of all points from their best-fitting plane below which
  // they count as coplanar: a single target plane cannot give a non-coplanar
  // calibration.
  double min_out_of_plane_mm = 1.0;
  int max_iterations = 200;  // Levenberg-Marquardt iterations

  // True when the numbers are usable; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

// Thesis 2.3, eq. 2.19: the linear camera matrix and its decomposition.
struct DltSolution {
  Matrix34d matrix = Matrix34d::Zero();  // C, scaled so that |C(2, 0..2)| = 1
  // C = k [rotation | translation]; k upper triangular, k(2, 2) = 1, positive
  // diagonal; k(0, 1) is the skew, which the pinhole model leaves out.
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // mm
  double rms_px = 0.0;  // RMS of the 2-D reprojection error over the points
};

// Linear 11-parameter solution (thesis eq. 2.19, c34 = 1) on Hartley-normalised
// data, then RQ decomposition. Throws CalibrationError when there are fewer
// than 6 points, any is not finite, or the points are coplanar / degenerate.
DltSolution SolveDlt(const std::vector<Eigen::Vector3d>& world_mm,
                     const std::vector<Eigen::Vector2d>& image_px);

// Tsai's linear stage (RAC, then f and tz), distortion taken as zero.
struct TsaiLinearSolution {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // mm
  double f_px = 0.0;                                      // fy
  double sx = 1.0;                                        // uncertainty scale factor, fx / fy
  double rms_px = 0.0;  // RMS 2-D reprojection error of this distortion-free camera
};

// Thesis 6.1 / Tsai 1987 non-coplanar RAC for the given principal point.
// Solved in homogeneous form (|r2| = 1) rather than divided by ty as in the
// paper, so that a world origin on the camera's y = 0 plane (ty = 0, as in
// the thesis rig) is not singular. Throws CalibrationError on too few, non-
// finite, coplanar or degenerate input, or when f comes out negative
// (mirrored image or world axes).
TsaiLinearSolution SolveTsaiLinear(const std::vector<Eigen::Vector3d>& world_mm,
                                   const std::vector<Eigen::Vector2d>& image_px,
                                   const Eigen::Vector2d& principal_point_px);

// Standard deviations of the refined parameters from the final Jacobian,
// (J^T J)^-1 times the residual variance; 0 for parameters held fixed.
struct CameraParameterSigmas {
  double f_px = 0.0;
  double sx = 0.0;
  double fx_px = 0.0;  // propagated from f and sx with their covariance
  double fy_px = 0.0;
  double cx_px = 0.0;
  double cy_px = 0.0;
  double k1 = 0.0;
  double k2 = 0.0;
  Eigen::Vector3d rotation_rad = Eigen::Vector3d::Zero();  // small rotations about device x, y, z
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();
};

// Where the refinement started.
enum class CameraInitialisation { kTsai, kDlt };

// How well the model fits (thesis Table 6.1). Pixel errors are the 2-D
// distances between detected and reprojected points (the RMS is over points,
// as cv::calibrateCamera reports it); mm errors are the distances on each
// point's own z plane between the true point and the detection back-projected
// onto that plane.
struct CameraCalibrationReport {
  int num_points = 0;
  int num_views = 0;
  double rms_px = 0.0;
  double max_px = 0.0;
  double rms_mm = 0.0;
  double max_mm = 0.0;
  std::vector<double> view_rms_px;  // one per input view (0 for an empty view)
  std::vector<double> view_rms_mm;
  double residual_sigma_px = 0.0;  // sqrt(SSR / (2N - free parameters)), per axis
  // Parameter standard deviations; nullopt when the data do not determine
  // every free parameter (e.g. k2 with a target in the image centre only).
  std::optional<CameraParameterSigmas> sigmas;
  double f_px = 0.0;  // refined Tsai parameters; fx = sx * f, fy = f
  double sx = 1.0;
  CameraInitialisation initialisation = CameraInitialisation::kTsai;
  DltSolution dlt;                         // stage 1
  std::optional<TsaiLinearSolution> tsai;  // stage 2 (linear part); nullopt if it failed
  std::string tsai_failure;                // why stage 2 failed, when it did
  int iterations = 0;
  bool converged = false;
};

struct CameraCalibration {
  geometry::PinholeModel model;  // pixels, our distortion convention
  CameraCalibrationReport report;
};

// Thesis 6.1: Tsai two-stage calibration of one camera from target views at
// several z (non-coplanar overall). Throws CalibrationError naming the reason.
CameraCalibration CalibrateCamera(const std::vector<TargetView>& views, int width, int height,
                                  const CameraCalibrationParams& params = {});

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_CAMERA_CALIBRATION_H_
