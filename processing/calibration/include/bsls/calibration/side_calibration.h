// The calibration of one side (one camera + its brick slide) from a session
// manifest (contracts section 4; thesis chapter 6):
//
//   1. camera     DetectTarget in every camera view, then CalibrateCamera
//                 (thesis 6.1, Tsai two-stage) on the views whose full grid
//                 was found.
//   2. stripes    Decode every screen view with the side's brick slide; every
//                 labelled line-centre sample of a decoded view is
//                 back-projected onto its screen z (camera ray ∩ plane
//                 z = z_mm): a StripePoint of line p (thesis 6.2: "the
//                 intersection of the corresponding camera rays with the
//                 appropriate reference plane").
//   3. planes     FitParallelPlaneModel (thesis 6.2.1) and
//                 FitPerspectivePlaneModel (6.2.2) on those points, each with
//                 the two-pass outlier rejection.
//   4. rows       When slide-1 (cross) views are given: the cross centre in
//                 each is slide point (s, t) = (0, 0), which is brick line 0
//                 and brick row v = 0 (contracts sections 1-2). Back-projected
//                 onto their screens, the centres lie on the projector ray of
//                 that slide point (the reference ray). Where the ray meets a
//                 screen view's plane, its image point is the junction (0, 0):
//                 the decoded line-0 junction nearest it fixes that view's even
//                 q offset (decoder::DecodeParams::q_offset).
//   5. projector  The junctions of the views with known offsets,
//                 back-projected onto their screens, give FitProjectorMatrix
//                 (thesis eq. 2.16) in slide units.
//
// A view that gives nothing usable is dropped, not fatal: a camera view whose
// target grid is not fully found (a view is never used in part), a screen view
// that does not decode, a cross view whose cross is not found or whose centre
// lies off the line through the others (when enough others agree to tell which
// is wrong). Each is named in SideCalibration::dropped_views with the reason,
// and the calibration goes on while enough views of its kind remain
// (SideCalibrationParams::min_*_views; docs/calibration.md says why those
// numbers).
//
// Frames and units: world millimetres of contracts section 3 (fixed by the
// target), image pixels with the origin at the centre of the top-left pixel,
// slide coordinates in line pitches d (bsls/pattern/brick_pattern.h).
//
// Errors: every failure throws CalibrationError whose what() names the input
// (manifest file, view image) and the reason: listed views out of z order or
// fewer than the minimum, an image that cannot be read or has another size,
// fewer usable views of a kind than its minimum once the bad ones are dropped
// (naming every dropped view and why), a fit that is degenerate or does not
// converge.
//
// Thread-safety: CalibrateSide is a pure function of its arguments (it reads
// the listed image files); decoding runs on OpenCV's thread pool.
#ifndef BSLS_CALIBRATION_SIDE_CALIBRATION_H_
#define BSLS_CALIBRATION_SIDE_CALIBRATION_H_

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/calibration/calibration_error.h"
#include "bsls/calibration/camera_calibration.h"
#include "bsls/calibration/manifest.h"
#include "bsls/calibration/projector_calibration.h"
#include "bsls/calibration/reference_cross.h"
#include "bsls/calibration/target_detect.h"
#include "bsls/common/cancellation.h"
#include "bsls/decoder/decoder.h"
#include "bsls/geometry/pinhole_model.h"
#include "bsls/io/frame_file.h"
#include "bsls/pattern/brick_pattern.h"

namespace bsls::calibration {

struct SideCalibrationParams {
  TargetDetectParams target;       // step 1, per camera view
  CameraCalibrationParams camera;  // step 1
  // Step 2. Its spec is replaced by the manifest's pattern and its q_offset
  // must be unset: the offsets come from the cross views. The decoder's
  // default chain, as for labels and surfaces (docs/decoding.md, "Which
  // chain").
  decoder::DecodeParams decode;
  StripeFitParams stripes;       // step 3, both plane models
  CrossParams cross;             // step 4
  ProjectorMatrixParams matrix;  // step 5
  // The fewest usable views of each kind (listed, and left once the views
  // that give nothing are dropped) that still calibrate; docs/calibration.md,
  // "Views that fail", says why. Camera views: two planes at distinct z make
  // the target points non-coplanar (Tsai's method needs that), a third checks
  // the depth direction so a view's residual means something. Screen views
  // (all at distinct z): two depths determine each light plane (two lines of
  // it), a third gives it a residual. Cross views, when any are listed: two
  // determine the reference ray, which fixes every screen view's rows.
  // The views' images (io::LoadGreyFrame): bsls-processd sets max_pixels to
  // its frame budget (max_frame_pixels), so an upload cannot make it decode
  // and search images larger than the frames it takes.
  io::FrameLimits images;
  int min_camera_views = 3;                 // >= 2
  int min_screen_views = 3;                 // >= 2
  int min_reference_views = 2;              // >= 2
  int stripe_sample_step = 1;               // use every n-th line-centre sample (rows), >= 1
  bool use_interpolated_junctions = false;  // step 5: also junctions the decoder placed unseen
  // Step 4: the decoded line-0 junction must lie this close (px) to the image
  // of the reference ray on a screen, else that view's offset stays unknown.
  // Line-0 junctions are 2 d apart (about 50 px in the thesis rig).
  double max_origin_junction_px = 8.0;  // > 0
  // Step 4: a cross centre further (mm) from the line fitted through the
  // others is a cross misread or a screen z misreported. With four or more
  // crosses, the one whose removal leaves the rest within this limit is
  // dropped; with fewer, nothing tells which is wrong and the calibration is
  // refused.
  double max_reference_ray_residual_mm = 1.0;  // > 0
  // Stripe-centre noise estimate: per line and view, a polynomial x(y) of
  // this degree is fitted to the centres; runs shorter than
  // min_centre_run samples are skipped.
  int centre_fit_degree = 3;  // 1..5
  int min_centre_run = 20;    // > centre_fit_degree + 1

  // True when every part is usable; otherwise names the field and why.
  bool IsValid(std::string* error) const;
};

// The three kinds of view a manifest lists (contracts section 4).
enum class ViewKind {
  kCamera,     // camera_views: the target
  kScreen,     // screen_views: the brick slide on a blank screen
  kReference,  // reference_views: slide 1 (the cross) on a blank screen
};

// "camera", "screen" or "reference": the manifest's names.
std::string_view ToString(ViewKind kind);

// A listed view left out of the calibration, and why.
struct DroppedView {
  std::filesystem::path image;
  ViewKind kind = ViewKind::kCamera;
  int index = 0;  // 0-based, in the manifest's list of its kind
  double z_mm = 0.0;
  std::string reason;  // e.g. "the brick pattern could not be decoded: reference line not found"
};

// How one camera view fed step 1.
struct CameraViewReport {
  std::filesystem::path image;
  double z_mm = 0.0;
  double rms_px = 0.0;             // reprojection error over the view's squares
  double rms_mm = 0.0;             // on the view's plane
  double max_grid_residual = 0.0;  // cells, DetectTarget
};

// How one screen view fed steps 2-5.
struct ScreenViewReport {
  std::filesystem::path image;
  double z_mm = 0.0;
  int lines = 0;                // labelled lines decoded
  int stripe_points = 0;        // line-centre samples back-projected
  int junctions = 0;            // labelled junctions decoded
  double plane_rms_mm = 0.0;    // perspective model, this view's kept points
  std::optional<int> q_offset;  // even; added to the decode's relative q (step 4)
  int matrix_junctions = 0;     // junctions that fed step 5
  // RMS slide reprojection error (line pitches d) of this view's junctions
  // that the projector matrix kept; nullopt without a matrix or junctions.
  std::optional<double> matrix_rms_d;
};

// A cross view of step 4.
struct ReferenceViewReport {
  std::filesystem::path image;
  double z_mm = 0.0;
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  // image of slide point (0, 0)
  Eigen::Vector3d world_mm = Eigen::Vector3d::Zero();   // back-projected onto z_mm
  // Distance from the fitted reference ray; 0 by construction with only two
  // crosses (the ray goes through both).
  double ray_residual_mm = 0.0;
};

// The projector ray of slide point (0, 0) (brick line 0, row 0): a world line.
struct ReferenceRay {
  Eigen::Vector3d point_mm = Eigen::Vector3d::Zero();    // on the line, at z = 0
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit, towards +z
  // Where the line meets the plane z = z_mm; nullopt when it is parallel to it.
  std::optional<Eigen::Vector3d> AtZ(double z_mm) const;
};

// Where the projector is (thesis Table 6.2: "the values for P0 and the
// projector axis", projector-to-origin distance).
struct ProjectorPose {
  // Perspective plane model: P0 (one point of the pencil axis: the stripes
  // alone cannot say where on it the projector lies) and the axis direction.
  Eigen::Vector3d plane_centre_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d plane_axis = Eigen::Vector3d::UnitY();
  double plane_centre_distance_mm = 0.0;  // |P0|
  // Projector matrix (when fitted): the full centre and the optical axis
  // (unit, world, from the projector towards the scene).
  std::optional<Eigen::Vector3d> matrix_centre_mm;
  std::optional<Eigen::Vector3d> optical_axis;
  std::optional<double> matrix_centre_distance_mm;  // |centre|
  // Angle (deg) between the camera's and the projector's optical axes
  // (thesis Table 6.3), when the matrix is fitted.
  std::optional<double> camera_projector_angle_deg;
};

// What reconstruction needs to attach an uncertainty to its points.
struct UncertaintySigmas {
  // Scatter (px, 1 sigma, along image x) of decoded line centres about a
  // smooth curve per line and view: the stripe-centre noise.
  double stripe_centre_px = 0.0;
  // Scatter (px, per axis) of target centres about the camera model.
  double target_point_px = 0.0;
  // RMS distance (mm) of screen points from their perspective-model plane.
  double plane_mm = 0.0;
};

// Wall-clock time of the steps, milliseconds.
struct SideCalibrationTimes {
  double camera_ms = 0.0;     // loading, detection, Tsai
  double stripes_ms = 0.0;    // loading and decoding the screen views
  double planes_ms = 0.0;     // both plane models
  double reference_ms = 0.0;  // crosses, offsets, projector matrix
  double total_ms = 0.0;
};

// The calibration of one side. Everything but `diagnostics` goes into the
// calibration file (calibration_file.h); after loading, the per-point flags
// (`inlier`) and the linear stages (`dlt`, `tsai`) of the reports are empty.
struct SideCalibration {
  pattern::Side side = pattern::Side::kLeft;
  int width = 0;  // image size, pixels
  int height = 0;
  std::string manifest_sha256;
  pattern::PatternSpec pattern;
  TargetGeometry target;
  CameraCalibration camera;                            // pixels
  ParallelPlaneFit parallel;                           // thesis 6.2.1
  PerspectivePlaneFit perspective;                     // thesis 6.2.2
  std::optional<ProjectorMatrixFit> projector_matrix;  // eq. 2.16, slide units d
  std::optional<ReferenceRay> reference_ray;
  std::vector<CameraViewReport> camera_views;        // manifest order
  std::vector<ScreenViewReport> screen_views;        // manifest order
  std::vector<ReferenceViewReport> reference_views;  // manifest order
  // Listed views left out (kind by kind in the order above, manifest order
  // within a kind); the *_views above hold only the views that were used.
  std::vector<DroppedView> dropped_views;
  ProjectorPose projector;
  UncertaintySigmas sigmas;

  // Not stored in the calibration file.
  struct Diagnostics {
    std::vector<StripePoint> stripe_points;      // step 2, in screen-view order
    std::vector<JunctionPoint> junction_points;  // step 5
    SideCalibrationTimes times;
  } diagnostics;
};

// Contracts section 4: two sides calibrated against the same target positions
// share one world frame. The files cannot show the positions, but one
// projector serves both sides, so in a shared frame the two calibrations put
// it in the same place: true when the targets match, the sides differ and the
// projector centres (projector matrices when both have one, else the points
// P0 of the perspective models) and reference rays (when both have one, at
// z = 0) lie within tolerance_mm of each other; otherwise false with the reason.
bool SharesWorldFrame(const SideCalibration& left, const SideCalibration& right, std::string* why,
                      double tolerance_mm = 5.0);

// Called before each view is read with its name and the fraction of the
// views begun; returning false stops the calibration (CalibrationError
// kCancelled).
using CalibrationProgress = std::function<bool(const std::string& view, double fraction)>;

// Thesis chapter 6 for one side: every step above. Throws CalibrationError
// naming the manifest or the view and the reason; Cancelled when `cancel`
// asks to stop (before each view and inside each view's decode).
SideCalibration CalibrateSide(const Manifest& manifest, const SideCalibrationParams& params = {},
                              const CalibrationProgress& progress = {},
                              const Cancellation& cancel = {});

// The projector pose of thesis Table 6.2 from the fitted models (step 5
// optional). Pure; used by CalibrateSide and after loading a file.
ProjectorPose PoseOfProjector(const PerspectivePlaneFit& perspective,
                              const std::optional<ProjectorMatrixFit>& matrix,
                              const geometry::PinholeModel& camera);

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_SIDE_CALIBRATION_H_
