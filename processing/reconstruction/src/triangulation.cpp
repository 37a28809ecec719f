#include "bsls/reconstruction/triangulation.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace bsls::reconstruction {
namespace {

// px: step of the central differences of the image derivatives. The point is
// smooth in the image coordinates on this scale (distortion and plane are
// smooth), so the truncation error is O(step^2) relative, ~1e-4.
constexpr double kImageStepPx = 1e-2;
// d: the same for slide coordinates (a pixel is ~0.05 d in the thesis set-up).
constexpr double kSlideStepD = 5e-4;
// Rays closer to parallel than this (sine of their angle) do not intersect.
constexpr double kMinRaySine = 1e-6;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

bool NonNegative(double v) { return std::isfinite(v) && v >= 0.0; }
bool Positive(double v) { return std::isfinite(v) && v > 0.0; }

// Adds J J^T sigma^2 of one error source to `covariance`.
void AddSource(const Eigen::Vector3d& derivative, double sigma, Eigen::Matrix3d* covariance) {
  if (sigma > 0.0) *covariance += derivative * derivative.transpose() * (sigma * sigma);
}

// The two rows of thesis eq. 2.18 for one device: (r1 - x r3) . X = x t3 - t1
// and (r2 - y r3) . X = y t3 - t2, with (x, y) ideal normalised coordinates.
void DeviceRows(const geometry::PinholeModel& device, const Eigen::Vector2d& normalised,
                double weight, Eigen::Matrix<double, 4, 3>* a, Eigen::Vector4d* b, int row) {
  const Eigen::Matrix3d& r = device.pose().rotation;
  const Eigen::Vector3d& t = device.pose().translation;
  for (int k = 0; k < 2; ++k) {
    a->row(row + k) = weight * (r.row(k) - normalised[k] * r.row(2));
    (*b)[row + k] = weight * (normalised[k] * t[2] - t[k]);
  }
}

// Thesis eq. 2.18 on ideal normalised coordinates of both devices (their
// undistortion done once by the caller): IntersectCameraAndProjectorRays.
// Each pass solves the 3 x 3 normal equations of the four rows (the rays
// are checked to cross at an angle first, so they are well conditioned).
std::optional<Eigen::Vector3d> IntersectNormalised(const geometry::PinholeModel& camera,
                                                   const Eigen::Vector2d& camera_n,
                                                   const geometry::PinholeModel& projector,
                                                   const Eigen::Vector2d& projector_n) {
  auto direction = [](const geometry::PinholeModel& device, const Eigen::Vector2d& n) {
    return (device.pose().rotation.transpose() * Eigen::Vector3d(n.x(), n.y(), 1.0)).normalized();
  };
  if (direction(camera, camera_n).cross(direction(projector, projector_n)).norm() < kMinRaySine)
    return std::nullopt;
  // A row's residual is the normalised error times the point's depth in
  // that device; dividing by the depth (from the previous solve, 1 at
  // first) makes it a distance in mm, so that both rays weigh alike. Two
  // reweighted solves settle the depths to far below a micron.
  double camera_depth = 1.0, projector_depth = 1.0;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int pass = 0; pass < 3; ++pass) {
    Eigen::Matrix<double, 4, 3> a;
    Eigen::Vector4d b;
    DeviceRows(camera, camera_n, pass == 0 ? 1.0 : 1.0 / camera_depth, &a, &b, 0);
    DeviceRows(projector, projector_n, pass == 0 ? 1.0 : 1.0 / projector_depth, &a, &b, 2);
    const Eigen::Matrix3d normal = a.transpose() * a;
    x = normal.ldlt().solve(a.transpose() * b);
    camera_depth = (camera.pose().rotation * x + camera.pose().translation).z();
    projector_depth = (projector.pose().rotation * x + projector.pose().translation).z();
    if (!(camera_depth > 0.0) || !(projector_depth > 0.0)) return std::nullopt;
  }
  if (!x.allFinite()) return std::nullopt;
  return x;
}

}  // namespace

LightPlaneFunction LightPlanesOfProjector(const geometry::PinholeModel& projector,
                                          pattern::Side side, double t_half_extent) {
  return [projector, side, t_half_extent](int p) -> std::optional<calibration::LightPlane> {
    return calibration::LightPlaneOfSlideColumn(projector, pattern::SFromU(side, p), t_half_extent);
  };
}

LightPlaneFunction LightPlanesOfModel(const calibration::ParallelPlaneModel& model) {
  return [model](int p) -> std::optional<calibration::LightPlane> { return model.PlaneOfLine(p); };
}

LightPlaneFunction LightPlanesOfModel(const calibration::PerspectivePlaneModel& model) {
  return [model](int p) -> std::optional<calibration::LightPlane> { return model.PlaneOfLine(p); };
}

bool UncertaintyParams::IsValid(std::string* error) const {
  const std::pair<const char*, double> fields[] = {
      {"stripe_centre_sigma_px", stripe_centre_sigma_px},
      {"junction_sigma_px", junction_sigma_px},
      {"camera_reprojection_sigma_px", camera_reprojection_sigma_px},
      {"light_plane_sigma_mm", light_plane_sigma_mm},
      {"projector_residual_sigma_d", projector_residual_sigma_d}};
  for (const auto& [name, value] : fields)
    if (!NonNegative(value))
      return Fail(error, std::string("uncertainty: ") + name + " must be finite and >= 0");
  return true;
}

double GeometricSetupParams::ProjectedLinePitchMm() const {
  // Thesis eq. 2.11-2.12: d0 = dg beta_p, beta_p = dp / (slide-to-lens distance).
  return slide_pitch_mm * projector_distance_mm / projector_slide_distance_mm;
}

bool GeometricSetupParams::IsValid(std::string* error) const {
  const std::pair<const char*, double> positive[] = {
      {"projector_distance_mm", projector_distance_mm},
      {"camera_distance_mm", camera_distance_mm},
      {"camera_projector_distance_mm", camera_projector_distance_mm},
      {"camera_focal_px", camera_focal_px},
      {"slide_pitch_mm", slide_pitch_mm},
      {"projector_slide_distance_mm", projector_slide_distance_mm}};
  for (const auto& [name, value] : positive)
    if (!Positive(value))
      return Fail(error, std::string("geometric set-up: ") + name + " must be positive");
  if (!std::isfinite(camera_angle_deg) || camera_angle_deg <= 0.0 || camera_angle_deg >= 80.0)
    return Fail(error, "geometric set-up: camera_angle_deg must be in (0, 80)");
  if (!std::isfinite(principal_x_px) || !std::isfinite(principal_y_px))
    return Fail(error, "geometric set-up: the principal point must be finite");
  if (!std::isfinite(camera_k1) || std::abs(camera_k1) > 1.0)
    return Fail(error, "geometric set-up: camera_k1 must be in [-1, 1]");
  return true;
}

bool TriangulationModel::IsValid(std::string* error) const {
  if (!uncertainty.IsValid(error)) return false;
  if (const auto* setup = std::get_if<GeometricSetupParams>(&geometry))
    return setup->IsValid(error);
  const auto& calibrated = std::get<CalibratedGeometry>(geometry);
  std::string why;
  if (!calibrated.camera.intrinsics().IsValid(&why))
    return Fail(error, "triangulation model: camera: " + why);
  if (!calibrated.light_plane) return Fail(error, "triangulation model: no light-plane function");
  if (calibrated.projector && !calibrated.projector->intrinsics().IsValid(&why))
    return Fail(error, "triangulation model: projector: " + why);
  return true;
}

geometry::PinholeModel CameraOfSetup(const GeometricSetupParams& setup, pattern::Side side) {
  // Thesis Figure 2.3: the camera at (sign dcp, 0, dc) looking down at theta
  // from -z towards the projector axis; sign = -1 on the left side.
  const double sign = side == pattern::Side::kLeft ? -1.0 : 1.0;
  const double theta = setup.camera_angle_deg * M_PI / 180.0;
  const double s = std::sin(theta), c = std::cos(theta);
  const Eigen::Vector3d axis(-sign * s, 0.0, -c);       // device z
  const Eigen::Vector3d image_y(0.0, -1.0, 0.0);        // device y
  const Eigen::Vector3d image_x = image_y.cross(axis);  // device x = y x z
  geometry::Pose pose;
  pose.rotation.row(0) = image_x.transpose();
  pose.rotation.row(1) = image_y.transpose();
  pose.rotation.row(2) = axis.transpose();
  const Eigen::Vector3d centre(sign * setup.camera_projector_distance_mm, 0.0,
                               setup.camera_distance_mm);
  pose.translation = -pose.rotation * centre;
  geometry::Intrinsics intrinsics;
  intrinsics.fx = intrinsics.fy = setup.camera_focal_px;
  intrinsics.cx = setup.principal_x_px;
  intrinsics.cy = setup.principal_y_px;
  intrinsics.k1 = setup.camera_k1;
  intrinsics.k2 = 0.0;
  return geometry::PinholeModel(intrinsics, pose);
}

std::optional<Eigen::Vector3d> GeometricHeightPoint(const GeometricSetupParams& setup,
                                                    pattern::Side side,
                                                    const Eigen::Vector2d& image_px, int p,
                                                    double line_shift_mm) {
  const double sign = side == pattern::Side::kLeft ? -1.0 : 1.0;
  const double dc = setup.camera_distance_mm, dp = setup.projector_distance_mm;
  const double dcp = setup.camera_projector_distance_mm;
  const double tan_theta = std::tan(setup.camera_angle_deg * M_PI / 180.0);
  const double cos_theta = std::cos(setup.camera_angle_deg * M_PI / 180.0);
  // Thesis eq. 2.2-2.4: the image point in ideal normalised coordinates (the
  // thesis's beta_c s x_i / dc), distortion removed when k1 is known.
  geometry::Intrinsics intrinsics;
  intrinsics.fx = intrinsics.fy = setup.camera_focal_px;
  intrinsics.cx = setup.principal_x_px;
  intrinsics.cy = setup.principal_y_px;
  intrinsics.k1 = setup.camera_k1;
  const Eigen::Vector2d n = geometry::PinholeModel(intrinsics, {}).Undistort(image_px);
  // Thesis eq. 2.6: S = (x_l, y_l, 0), where the camera ray meets the base plane.
  const double denominator = 1.0 + sign * n.x() * tan_theta;
  if (!(denominator > kMinRaySine)) return std::nullopt;  // ray at or above the horizon
  const double x_l = sign * dcp + dc * (n.x() - sign * tan_theta) / denominator;
  const double y_l = -dc * n.y() / (cos_theta * denominator);
  // Thesis eq. 2.11: line p meets the base plane at x_k = s d0; its light plane
  // holds P = (0, 0, dp) and that line: x = x_k (1 - z / dp) (eq. 2.7).
  const double x_k = pattern::SFromU(side, p) * setup.ProjectedLinePitchMm() + line_shift_mm;
  // Thesis eq. 2.5, 2.8: H = C + t (S - C) on that plane.
  const double divisor = x_l - sign * dcp - x_k * dc / dp;
  if (std::abs(divisor) < kMinRaySine) return std::nullopt;
  const double t = (x_k * (1.0 - dc / dp) - sign * dcp) / divisor;
  if (!(t > 0.0)) return std::nullopt;
  return Eigen::Vector3d(sign * dcp + t * (x_l - sign * dcp), t * y_l, dc * (1.0 - t));
}

std::optional<Eigen::Vector3d> IntersectCameraAndProjectorRays(
    const geometry::PinholeModel& camera, const Eigen::Vector2d& image_px,
    const geometry::PinholeModel& projector, const Eigen::Vector2d& slide_st) {
  return IntersectNormalised(camera, camera.Undistort(image_px), projector,
                             projector.Undistort(slide_st));
}

Triangulator::Triangulator(TriangulationModel model) : model_(std::move(model)) {
  std::string why;
  if (!model_.IsValid(&why)) throw std::invalid_argument(why);
  if (const auto* setup = std::get_if<GeometricSetupParams>(&model_.geometry))
    camera_ = CameraOfSetup(*setup, model_.side);
  else
    camera_ = std::get<CalibratedGeometry>(model_.geometry).camera;
}

bool Triangulator::HasProjector() const {
  const auto* calibrated = std::get_if<CalibratedGeometry>(&model_.geometry);
  return calibrated && calibrated->projector.has_value();
}

Eigen::Vector3d Triangulator::CameraCentre() const { return camera_.Centre(); }

std::optional<Eigen::Vector3d> Triangulator::LinePoint(
    int p, const Eigen::Vector2d& image_px, const std::optional<calibration::LightPlane>& plane,
    double plane_shift_mm) const {
  if (const auto* setup = std::get_if<GeometricSetupParams>(&model_.geometry)) {
    // A perpendicular shift of the plane x = x_k (1 - z / dp) moves its foot
    // on the base plane by shift * sqrt(dp^2 + x_k^2) / dp.
    const double dp = setup->projector_distance_mm;
    const double x_k = pattern::SFromU(model_.side, p) * setup->ProjectedLinePitchMm();
    const double foot_shift = plane_shift_mm * std::hypot(dp, x_k) / dp;
    return GeometricHeightPoint(*setup, model_.side, image_px, p, foot_shift);
  }
  calibration::LightPlane shifted = *plane;
  shifted.offset_mm += plane_shift_mm;
  return shifted.Intersect(camera_.BackProject(image_px));
}

std::optional<TriangulatedPoint> Triangulator::LineSample(int p, const Eigen::Vector2d& image_px,
                                                          double centre_sigma_px) const {
  std::optional<calibration::LightPlane> plane;
  if (const auto* calibrated = std::get_if<CalibratedGeometry>(&model_.geometry)) {
    plane = calibrated->light_plane(p);
    if (!plane) return std::nullopt;
  }
  const std::optional<Eigen::Vector3d> point = LinePoint(p, image_px, plane, 0.0);
  if (!point) return std::nullopt;
  const UncertaintyParams& u = model_.uncertainty;
  if (centre_sigma_px < 0.0) centre_sigma_px = u.stripe_centre_sigma_px;

  // Derivatives by central differences; a missing neighbour (the point sits
  // at the edge of where the plane is hit) falls back to a one-sided one.
  auto derivative = [&](const Eigen::Vector2d& image_step, double plane_step) -> Eigen::Vector3d {
    const auto ahead = LinePoint(p, image_px + image_step, plane, plane_step);
    const auto behind = LinePoint(p, image_px - image_step, plane, -plane_step);
    const double h = image_step.norm() + std::abs(plane_step);
    if (ahead && behind) return (*ahead - *behind) / (2.0 * h);
    if (ahead) return (*ahead - *point) / h;
    if (behind) return (*point - *behind) / h;
    return Eigen::Vector3d::Zero();
  };
  const Eigen::Vector3d d_x = derivative({kImageStepPx, 0.0}, 0.0);
  const Eigen::Vector3d d_y = derivative({0.0, kImageStepPx}, 0.0);
  Eigen::Vector3d d_plane;
  if (plane) {
    // Analytic: X = C + lambda d with n.X = offset gives dX/d offset = d / (n.d).
    const Eigen::Vector3d direction = camera_.BackProject(image_px).direction;
    d_plane = direction / plane->normal.dot(direction);
  } else {
    d_plane = derivative(Eigen::Vector2d::Zero(), 1e-2);
  }
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  AddSource(d_x, centre_sigma_px, &covariance);
  AddSource(d_x, u.camera_reprojection_sigma_px, &covariance);
  AddSource(d_y, u.camera_reprojection_sigma_px, &covariance);
  AddSource(d_plane, u.light_plane_sigma_mm, &covariance);
  return TriangulatedPoint{*point, std::sqrt(covariance.trace())};
}

std::optional<TriangulatedPoint> Triangulator::Junction(int p, int q,
                                                        const Eigen::Vector2d& image_px,
                                                        bool q_is_slide_row) const {
  const UncertaintyParams& u = model_.uncertainty;
  if (!HasProjector() || !q_is_slide_row) {
    // As a line sample with the junction's error along the row; its error
    // along the column adds sigma_y^2 |dX/dy|^2.
    std::optional<TriangulatedPoint> point = LineSample(p, image_px, u.junction_sigma_px);
    if (!point) return std::nullopt;
    const Eigen::Vector2d step(0.0, kImageStepPx);
    const auto below = LineSample(p, image_px + step, 0.0);
    const auto above = LineSample(p, image_px - step, 0.0);
    if (below && above) {
      const Eigen::Vector3d d_y = (below->position - above->position) / (2.0 * kImageStepPx);
      point->sigma_mm = std::sqrt(point->sigma_mm * point->sigma_mm +
                                  d_y.squaredNorm() * u.junction_sigma_px * u.junction_sigma_px);
    }
    return point;
  }
  const geometry::PinholeModel& projector =
      *std::get<CalibratedGeometry>(model_.geometry).projector;
  const Eigen::Vector2d slide = calibration::SlideOfJunction(model_.side, p, q);
  // Each device's point undistorted once; each step below moves one of them.
  const Eigen::Vector2d camera_n = camera_.Undistort(image_px);
  const Eigen::Vector2d projector_n = projector.Undistort(slide);
  const auto moving_camera = [&](const Eigen::Vector2d& image) {
    return IntersectNormalised(camera_, camera_.Undistort(image), projector, projector_n);
  };
  const auto moving_projector = [&](const Eigen::Vector2d& st) {
    return IntersectNormalised(camera_, camera_n, projector, projector.Undistort(st));
  };
  const std::optional<Eigen::Vector3d> point =
      IntersectNormalised(camera_, camera_n, projector, projector_n);
  if (!point) return std::nullopt;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  const double image_sigma2 = u.junction_sigma_px * u.junction_sigma_px +
                              u.camera_reprojection_sigma_px * u.camera_reprojection_sigma_px;
  for (int axis = 0; axis < 2; ++axis) {
    Eigen::Vector2d step = Eigen::Vector2d::Zero();
    step[axis] = kImageStepPx;
    const auto a = moving_camera(image_px + step), b = moving_camera(image_px - step);
    if (a && b) AddSource((*a - *b) / (2.0 * kImageStepPx), std::sqrt(image_sigma2), &covariance);
    Eigen::Vector2d slide_step = Eigen::Vector2d::Zero();
    slide_step[axis] = kSlideStepD;
    const auto c = moving_projector(slide + slide_step), d = moving_projector(slide - slide_step);
    if (c && d)
      AddSource((*c - *d) / (2.0 * kSlideStepD), u.projector_residual_sigma_d, &covariance);
  }
  return TriangulatedPoint{*point, std::sqrt(covariance.trace())};
}

}  // namespace bsls::reconstruction
