// Non-linear refinement of a pinhole model (geometry::PinholeModel, our
// distortion convention: ideal -> distorted) from world <-> image
// correspondences, shared by the camera (thesis 6.1, Tsai's final stage) and
// the projector matrix (thesis 2.3 eq. 2.16 refined). Internal to
// bsls_calibration.
//
// Parameter vector (index = PinholeParam):
//   focal_a, focal_b  FocalForm::kFSx: f = fy and sx = fx / fy (Tsai's
//                     uncertainty scale factor); FocalForm::kFxFy: fx and fy.
//   cx, cy            principal point, image units.
//   k1, k2            radial distortion.
//   wx, wy, wz        rotation vector w: R = exp([w]x) * R_ref, i.e. a small
//                     rotation about the DEVICE axes applied after R_ref.
//   tx, ty, tz        translation world -> device, mm.
// Covariances are evaluated at the optimum with R_ref = the final
// rotation (w = 0), so the rotation ones are radians about device axes.
#ifndef BSLS_CALIBRATION_SRC_PINHOLE_REFINEMENT_H_
#define BSLS_CALIBRATION_SRC_PINHOLE_REFINEMENT_H_

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "bsls/geometry/pinhole_model.h"
#include "levenberg_marquardt.h"

namespace bsls::calibration::internal {

enum PinholeParam {
  kFocalA,
  kFocalB,
  kCx,
  kCy,
  kK1,
  kK2,
  kWx,
  kWy,
  kWz,
  kTx,
  kTy,
  kTz,
  kPinholeParamCount
};

enum class FocalForm { kFSx, kFxFy };

using PinholeVector = Eigen::Matrix<double, kPinholeParamCount, 1>;
using PinholeMatrix = Eigen::Matrix<double, kPinholeParamCount, kPinholeParamCount>;

struct PinholeRefinement {
  geometry::PinholeModel model;
  // Covariance of the parameters (rows/columns of fixed ones are 0); nullopt
  // when the free parameters are not all determined by the data.
  std::optional<PinholeMatrix> covariance;
  double residual_sigma = 0.0;  // sqrt(SSR / (2N - free)), image units per axis
  Eigen::VectorXd residuals;    // (du0, dv0, du1, dv1, ...), model - observed
  int iterations = 0;
  bool converged = false;
};

// The rotation exp([w]x) of a rotation vector w (radians).
Eigen::Matrix3d RotationFromVector(const Eigen::Vector3d& w);

// Refines `initial` over the free parameters. nullopt when the initial model
// puts a point behind the device (the start is unusable).
std::optional<PinholeRefinement> RefinePinhole(const std::vector<Eigen::Vector3d>& world,
                                               const std::vector<Eigen::Vector2d>& image,
                                               const geometry::PinholeModel& initial,
                                               FocalForm form,
                                               const std::array<bool, kPinholeParamCount>& free,
                                               const LmOptions& options);

}  // namespace bsls::calibration::internal

#endif  // BSLS_CALIBRATION_SRC_PINHOLE_REFINEMENT_H_
