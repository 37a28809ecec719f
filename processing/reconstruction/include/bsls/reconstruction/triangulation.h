// Triangulation of labelled stripe samples and junctions into world points
// with a first-order uncertainty (thesis 2.2-2.3, 5.2).
//
//   (a) line samples      camera ray of the image point intersected with the
//                         light plane of its line p (thesis 2.3, 5.2);
//   (b) junctions         least-squares intersection of the camera ray and the
//                         projector ray of the junction's slide point (thesis
//                         eq. 2.18) when a projector matrix is known and q is
//                         the slide row; otherwise as (a);
//   (c) no calibration    the thesis's explicit height formula from the set-up
//                         distances and angle (thesis 2.2, eq. 2.1-2.12).
//
// Frames and units:
//   world   millimetres, contracts section 3 (x right, y up, z towards the
//           cameras; z = 0 is the base plane).
//   image   camera pixels, origin at the centre of the top-left pixel, x =
//           column, y = row (the decoder's coordinates).
//   slide   (s, t) in line pitches d (bsls/pattern/brick_pattern.h); the
//           projector model's image is the slide.
//
// Uncertainty: every point carries sigma_mm = sqrt(trace(Sigma)), the RMS 3-D
// position error (1 sigma) of the first-order covariance
//   Sigma = sum_k J_k J_k^T sigma_k^2
// over the independent error sources k of UncertaintyParams: the stripe centre
// along the image row (the decoder measures one centre per row), the camera
// calibration's reprojection error along both image axes, the light plane's
// offset (or, for junctions, the projector's slide residual along s and t).
// J_k is the derivative of the triangulated point with respect to source k,
// analytic for the plane offset and by central differences otherwise.
//
// Thread-safety: Triangulator is immutable after construction; its const
// members may be called concurrently (the light-plane function must allow it).
#ifndef BSLS_RECONSTRUCTION_TRIANGULATION_H_
#define BSLS_RECONSTRUCTION_TRIANGULATION_H_

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <string>
#include <variant>

#include "bsls/calibration/projector_calibration.h"
#include "bsls/geometry/pinhole_model.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::reconstruction {

// The light plane of line p, or nullopt when the calibration does not know p.
using LightPlaneFunction = std::function<std::optional<calibration::LightPlane>(int p)>;

// Light planes of a projector model (slide units): the plane of slide column
// SFromU(side, p) (calibration::LightPlaneOfSlideColumn), for every p.
LightPlaneFunction LightPlanesOfProjector(const geometry::PinholeModel& projector,
                                          pattern::Side side, double t_half_extent = 24.0);
// Light planes of a fitted parallel-plane model (thesis 6.2.1): PlaneOfLine(p).
LightPlaneFunction LightPlanesOfModel(const calibration::ParallelPlaneModel& model);
// Light planes of a fitted perspective-plane model (thesis 6.2.2): PlaneOfLine(p).
LightPlaneFunction LightPlanesOfModel(const calibration::PerspectivePlaneModel& model);

// The error sources propagated into each point's sigma (1 sigma each).
struct UncertaintyParams {
  // px, along the image row: the decoder's line-centre error (docs/decoding.md:
  // <= 0.1 px RMS at sensor noise sigma 3).
  double stripe_centre_sigma_px = 0.1;
  // px, each image axis: a junction's position error.
  double junction_sigma_px = 0.2;
  // px, each image axis: the camera calibration's reprojection error (its RMS
  // residual); 0 for a perfectly known camera.
  double camera_reprojection_sigma_px = 0.1;
  // mm: the light planes' point-to-plane residual (calibration
  // StripeFitReport::rms_mm); 0 for exact planes.
  double light_plane_sigma_mm = 0.05;
  // d, each slide axis: the projector matrix's reprojection residual
  // (ProjectorMatrixReport::residual_sigma_d); junctions by eq. 2.18 only.
  double projector_residual_sigma_d = 0.005;

  // True when every sigma is finite and >= 0; otherwise names the field.
  bool IsValid(std::string* error) const;
};

// A calibrated set-up (thesis 6): camera, light planes and optionally the
// projector matrix for junctions.
struct CalibratedGeometry {
  geometry::PinholeModel camera;  // pixels
  LightPlaneFunction light_plane;
  // Slide units d. When set, junctions whose q is the slide row are
  // triangulated with eq. 2.18.
  std::optional<geometry::PinholeModel> projector;
};

// Thesis 2.2 (Figures 2.2-2.4, Tables 2.1-2.2): the explicit set-up of the
// height formula, used when no calibration is available. The projector sits
// at (0, 0, dp) looking straight down with the reference line under it; the
// camera of the left side at (-dcp, 0, dc) (right side: (+dcp, 0, dc)), its
// optical axis tilted by theta from -z towards the projector axis in the xz
// plane, image x along world +x (tilted), image y along world -y. Line p lies
// on the base plane at x = s d0, s = SFromU(side, p), d0 = dg * beta_p (eq.
// 2.11). Lens distortion is not part of the thesis formula; camera_k1 allows
// one radial term (thesis 6.1) when it is known.
struct GeometricSetupParams {
  double projector_distance_mm = 730.0;         // dp: projector centre above the base plane
  double camera_distance_mm = 340.0;            // dc: camera centre above the base plane
  double camera_projector_distance_mm = 240.0;  // dcp: horizontal camera-projector distance
  double camera_angle_deg = 35.0;               // theta: camera optical axis to the z axis
  // fc / s: the camera focal length over its pixel pitch (the thesis's scale
  // factor s and amplification beta_c = dc / fc of eq. 2.3-2.4 in one number).
  double camera_focal_px = 901.12;
  double principal_x_px = 255.5;  // where the optical axis meets the image
  double principal_y_px = 255.5;
  double camera_k1 = 0.0;       // radial distortion, normalised coordinates; 0: none
  double slide_pitch_mm = 0.8;  // dg = dw + dB (eq. 2.10; Table 2.1: 0.1 + 0.7 mm)
  // The slide-to-lens distance: beta_p = dp / it (eq. 2.12 in pinhole form;
  // the thesis writes it fp + phi_p, 90 + 25 mm in Table 2.1).
  double projector_slide_distance_mm = 115.0;

  // d0 = dg * beta_p: the spacing of the projected lines on the base plane
  // (eq. 2.9, 2.11), mm.
  double ProjectedLinePitchMm() const;
  // True when the numbers describe a set-up; otherwise names the field.
  bool IsValid(std::string* error) const;
};

// Everything triangulation needs for one side.
struct TriangulationModel {
  pattern::Side side = pattern::Side::kLeft;
  std::variant<CalibratedGeometry, GeometricSetupParams> geometry;
  UncertaintyParams uncertainty;

  // True when the model can triangulate; otherwise names the part and why.
  bool IsValid(std::string* error) const;
};

// A triangulated point and its uncertainty.
struct TriangulatedPoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world mm
  double sigma_mm = 0.0;  // sqrt(trace) of the first-order covariance, mm
};

// Thesis eq. 2.18: the least-squares intersection of the camera ray through
// `image_px` and the projector ray through `slide_st`, as the solution of the
// four linear equations in ideal normalised coordinates, rows weighted by the
// inverse depth so that residuals are distances (mm) from the two rays.
// nullopt when the rays are (nearly) parallel.
std::optional<Eigen::Vector3d> IntersectCameraAndProjectorRays(
    const geometry::PinholeModel& camera, const Eigen::Vector2d& image_px,
    const geometry::PinholeModel& projector, const Eigen::Vector2d& slide_st);

// Thesis eq. 2.1-2.12: the point of line p seen at `image_px` from the set-up
// alone (camera ray to the base plane, eq. 2.5-2.6, intersected with the
// projector's plane of line p, eq. 2.7-2.8 and 2.11). `line_shift_mm` moves
// the line on the base plane (for the uncertainty). nullopt when the ray does
// not meet the plane in front of the camera.
std::optional<Eigen::Vector3d> GeometricHeightPoint(const GeometricSetupParams& setup,
                                                    pattern::Side side,
                                                    const Eigen::Vector2d& image_px, int p,
                                                    double line_shift_mm = 0.0);

// The camera model implied by a geometric set-up (pixels; its pose and
// intrinsics match GeometricHeightPoint's camera).
geometry::PinholeModel CameraOfSetup(const GeometricSetupParams& setup, pattern::Side side);

class Triangulator {
 public:
  // Throws std::invalid_argument naming the part when the model is invalid.
  explicit Triangulator(TriangulationModel model);

  // Line sample of line p at `image_px` (a) or (c); its sigma uses
  // `centre_sigma_px` along the image row (negative: the model's
  // stripe_centre_sigma_px). nullopt when p has no light plane or the ray
  // misses it.
  std::optional<TriangulatedPoint> LineSample(int p, const Eigen::Vector2d& image_px,
                                              double centre_sigma_px = -1.0) const;
  // Junction (p, q) at `image_px` (b): eq. 2.18 when the model has a
  // projector and q_is_slide_row; otherwise as a line sample of p with
  // junction_sigma_px on both image axes.
  std::optional<TriangulatedPoint> Junction(int p, int q, const Eigen::Vector2d& image_px,
                                            bool q_is_slide_row) const;
  // True when junctions with a slide-row q are triangulated by eq. 2.18.
  bool HasProjector() const;
  // The camera centre in world mm (faces are oriented towards it).
  Eigen::Vector3d CameraCentre() const;
  // The model it was built with.
  const TriangulationModel& model() const { return model_; }

 private:
  // The point of line p at an image point with the plane moved by
  // `plane_shift_mm` along its normal; nullopt when it does not exist.
  std::optional<Eigen::Vector3d> LinePoint(int p, const Eigen::Vector2d& image_px,
                                           const std::optional<calibration::LightPlane>& plane,
                                           double plane_shift_mm) const;

  TriangulationModel model_;
  geometry::PinholeModel camera_;  // the calibrated camera, or CameraOfSetup
};

}  // namespace bsls::reconstruction

#endif  // BSLS_RECONSTRUCTION_TRIANGULATION_H_
