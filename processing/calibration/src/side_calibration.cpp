#include "bsls/calibration/side_calibration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "bsls/common/errors.h"
#include "bsls/io/frame_file.h"
#include "point_set_geometry.h"

namespace bsls::calibration {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

[[noreturn]] void Throw(CalibrationErrorReason reason, const std::string& message) {
  throw CalibrationError(reason, message);
}

std::string Number(double value) {
  std::ostringstream os;
  os << value;
  return os.str();
}

// "target_z010.png (camera view 2, z = 10 mm)"
std::string ViewName(const std::filesystem::path& image, ViewKind kind, size_t index, double z_mm) {
  return image.string() + " (" + std::string(ToString(kind)) + " view " +
         std::to_string(index + 1) + ", z = " + Number(z_mm) + " mm)";
}

std::string ViewName(const ManifestView& view, ViewKind kind, size_t index) {
  return ViewName(view.image, kind, index, view.z_mm);
}

// Why a kind needs its minimum (SideCalibrationParams::min_*_views).
std::string WhyMinimum(ViewKind kind) {
  switch (kind) {
    case ViewKind::kCamera:
      return "two target planes at distinct z make the points non-coplanar for Tsai's method, a "
             "third gives the depth a residual";
    case ViewKind::kScreen:
      return "two depths determine each light plane, a third gives it a residual";
    case ViewKind::kReference:
      return "two cross centres determine the reference ray that fixes the slide rows";
  }
  return "";
}

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

// Reads a listed image as 8-bit grey of the session's size (the first image
// read sets it), within `limits`.
cv::Mat LoadView(const ManifestView& view, const std::string& name, const io::FrameLimits& limits,
                 int* width, int* height) {
  cv::Mat grey;
  try {
    grey = io::LoadGreyFrame(view.image.string(), nullptr, limits);
  } catch (const InputError& e) {
    Throw(CalibrationErrorReason::kUnreadableInput, "calibration: " + std::string(e.what()));
  }
  if (*width == 0) {
    *width = grey.cols;
    *height = grey.rows;
  } else if (grey.cols != *width || grey.rows != *height) {
    Throw(CalibrationErrorReason::kInvalidInput,
          "calibration: " + name + " is " + std::to_string(grey.cols) + " x " +
              std::to_string(grey.rows) + " px, the other views " + std::to_string(*width) + " x " +
              std::to_string(*height));
  }
  return grey;
}

// The listed views in the order and number the calibration needs.
void CheckManifest(const Manifest& manifest, const SideCalibrationParams& params) {
  const std::string file = manifest.path.string();
  if (static_cast<int>(manifest.camera_views.size()) < params.min_camera_views)
    Throw(CalibrationErrorReason::kInvalidInput,
          "calibration: " + file + " lists " + std::to_string(manifest.camera_views.size()) +
              " camera views; at least " + std::to_string(params.min_camera_views) + " are needed");
  if (static_cast<int>(manifest.screen_views.size()) < params.min_screen_views)
    Throw(CalibrationErrorReason::kInvalidInput,
          "calibration: " + file + " lists " + std::to_string(manifest.screen_views.size()) +
              " screen views; at least " + std::to_string(params.min_screen_views) + " are needed");
  // Cross views are optional; listed, they must be able to fix the rows.
  if (!manifest.reference_views.empty() &&
      static_cast<int>(manifest.reference_views.size()) < params.min_reference_views)
    Throw(CalibrationErrorReason::kInvalidInput,
          "calibration: " + file + " lists " + std::to_string(manifest.reference_views.size()) +
              " reference views; none or at least " + std::to_string(params.min_reference_views) +
              " are needed (" + WhyMinimum(ViewKind::kReference) + ")");
  // Contracts section 3: the target is moved along +z only, from z = 0.
  for (size_t i = 0; i < manifest.camera_views.size(); ++i) {
    const double z = manifest.camera_views[i].z_mm;
    if (!(z >= 0.0))
      Throw(CalibrationErrorReason::kInvalidInput,
            "calibration: " + file + ": camera view " + std::to_string(i + 1) + " has z_mm " +
                Number(z) + "; the target moves along +z from z = 0 only");
    if (i > 0 && !(z > manifest.camera_views[i - 1].z_mm))
      Throw(CalibrationErrorReason::kInvalidInput,
            "calibration: " + file + ": camera views are not in increasing z (view " +
                std::to_string(i + 1) + " at " + Number(z) + " mm follows " +
                Number(manifest.camera_views[i - 1].z_mm) + " mm)");
  }
  auto distinct = [&](const std::vector<ManifestView>& views, const char* what) {
    std::set<double> seen;
    for (const ManifestView& v : views)
      if (!seen.insert(v.z_mm).second)
        Throw(CalibrationErrorReason::kInvalidInput,
              "calibration: " + file + ": two " + what + " views at z = " + Number(v.z_mm) + " mm");
  };
  // Distinct z: the minimum counts are counts of depths.
  distinct(manifest.screen_views, "screen");
  distinct(manifest.reference_views, "reference");
}

// Pooled scatter (px) of line centres about a polynomial x(y) per run of
// consecutive rows; 0 when no run is long enough. `sum2` and `dof` accumulate.
void AccumulateCentreScatter(const std::vector<cv::Point2d>& points, int degree, int min_run,
                             double* sum2, double* dof) {
  size_t begin = 0;
  while (begin < points.size()) {
    size_t end = begin + 1;
    while (end < points.size() && points[end].y - points[end - 1].y <= 1.5) ++end;
    const int n = static_cast<int>(end - begin);
    if (n >= min_run) {
      const double y0 = 0.5 * (points[begin].y + points[end - 1].y);
      const double half = std::max(0.5 * (points[end - 1].y - points[begin].y), 1.0);
      Eigen::MatrixXd a(n, degree + 1);
      Eigen::VectorXd b(n);
      for (int i = 0; i < n; ++i) {
        const double t = (points[begin + i].y - y0) / half;
        double power = 1.0;
        for (int k = 0; k <= degree; ++k, power *= t) a(i, k) = power;
        b(i) = points[begin + i].x;
      }
      const Eigen::VectorXd coef = a.colPivHouseholderQr().solve(b);
      *sum2 += (a * coef - b).squaredNorm();
      *dof += n - (degree + 1);
    }
    begin = end;
  }
}

// Total-least-squares line through points: centroid and unit direction
// (towards +z).
ReferenceRay FitRay(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - centroid) * (p - centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  Eigen::Vector3d direction = eig.eigenvectors().col(2).normalized();
  if (direction.z() < 0.0) direction = -direction;
  ReferenceRay ray;
  ray.direction = direction;
  ray.point_mm = centroid;
  if (std::abs(direction.z()) > 1e-12) ray.point_mm = *ray.AtZ(0.0);
  return ray;
}

double DistanceToLine(const ReferenceRay& ray, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - ray.point_mm;
  return (d - d.dot(ray.direction) * ray.direction).norm();
}

// The points but the one at `skip`.
std::vector<Eigen::Vector3d> AllBut(const std::vector<ReferenceViewReport>& crosses, size_t skip) {
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < crosses.size(); ++i)
    if (i != skip) points.push_back(crosses[i].world_mm);
  return points;
}

// Largest distance of `points` from their own fitted ray.
double WorstOffRay(const std::vector<Eigen::Vector3d>& points) {
  const ReferenceRay ray = FitRay(points);
  double worst = 0.0;
  for (const auto& p : points) worst = std::max(worst, DistanceToLine(ray, p));
  return worst;
}

// One run of CalibrateSide: the manifest and params it reads, the calibration
// it fills, and the views announced so far. Each public step is one stage of
// thesis chapter 6; CalibrateSide calls them in their numbered order.
class SideCalibrationRun {
 public:
  SideCalibrationRun(const Manifest& manifest, const SideCalibrationParams& params,
                     const CalibrationProgress& progress, const Cancellation& cancel)
      : manifest_(manifest),
        params_(params),
        progress_(progress),
        cancel_(cancel),
        file_(manifest.path.string()),
        total_views_(static_cast<double>(manifest.camera_views.size() +
                                         manifest.screen_views.size() +
                                         manifest.reference_views.size())) {}

  // Throws unless the params, the manifest's target and pattern and its view
  // lists are fit to calibrate from.
  void CheckInputs() const;
  // 1. Thesis 6.1: camera model and camera view reports.
  void CalibrateCameraViews();
  // 2. Thesis 6.2: stripe points of the screen views; the decode of each used
  // screen view, in the order of out().screen_views.
  std::vector<decoder::DecodeResult> DecodeScreenViews();
  // 3. Thesis 6.2.1 and 6.2.2: both light-plane models and per-view plane RMS.
  void FitStripePlanes();
  // 4. Slide 1: the reference ray (when crosses are listed) and each screen
  // view's q offset.
  void FixSlideRows(const std::vector<decoder::DecodeResult>& decoded);
  // 5. Thesis eq. 2.16: the projector matrix, when crosses are listed.
  void FitMatrix(const std::vector<decoder::DecodeResult>& decoded);

  SideCalibration& out() { return out_; }

 private:
  void BeginView(const std::string& name);
  cv::Mat Load(const ManifestView& view, const std::string& name) {
    return LoadView(view, name, params_.images, &width_, &height_);
  }
  void Drop(const ManifestView& view, ViewKind kind, size_t index, const std::string& reason);
  void Require(ViewKind kind, size_t used, size_t listed, int minimum) const;
  [[noreturn]] void Rethrow(const CalibrationError& e) const;
  std::optional<ScreenViewReport> ScreenStripePoints(const ManifestView& view, size_t index,
                                                     const decoder::DecodeResult& result,
                                                     std::vector<StripePoint>* points, double* sum2,
                                                     double* dof);
  void FindCrosses();
  void RejectOffRayCrosses();
  void SetQOffsets(const std::vector<decoder::DecodeResult>& decoded);
  std::vector<size_t> CollectJunctionPoints(const std::vector<decoder::DecodeResult>& decoded);

  const Manifest& manifest_;
  const SideCalibrationParams& params_;
  const CalibrationProgress& progress_;
  const Cancellation& cancel_;
  const std::string file_;
  const double total_views_;
  int views_begun_ = 0;
  int width_ = 0, height_ = 0;
  std::vector<size_t> view_begin_;   // first stripe point of each used screen view, then the end
  std::vector<size_t> cross_index_;  // manifest index of each used cross view
  SideCalibration out_;
};

void SideCalibrationRun::CheckInputs() const {
  std::string why;
  if (!params_.IsValid(&why))
    Throw(CalibrationErrorReason::kInvalidParams, "calibration: parameters: " + why);
  if (!manifest_.target.IsValid(&why))
    Throw(CalibrationErrorReason::kInvalidInput, "calibration: " + file_ + ": " + why);
  if (!manifest_.pattern.IsValid(&why))
    Throw(CalibrationErrorReason::kInvalidInput, "calibration: " + file_ + ": pattern: " + why);
  CheckManifest(manifest_, params_);
}

// Every view is announced before it is read; the caller may stop there.
void SideCalibrationRun::BeginView(const std::string& name) {
  cancel_.ThrowIfRequested(name);
  if (progress_ && !progress_(name, views_begun_ / total_views_))
    Throw(CalibrationErrorReason::kCancelled, "calibration: stopped before " + name);
  ++views_begun_;
}

// A view that gives nothing is left out with its reason; a kind with fewer
// usable views than its minimum refuses the calibration, naming the views
// it lost and why.
void SideCalibrationRun::Drop(const ManifestView& view, ViewKind kind, size_t index,
                              const std::string& reason) {
  out_.dropped_views.push_back({view.image, kind, static_cast<int>(index), view.z_mm, reason});
}

void SideCalibrationRun::Require(ViewKind kind, size_t used, size_t listed, int minimum) const {
  if (static_cast<int>(used) >= minimum) return;
  std::string text = "calibration: " + file_ + ": " + std::to_string(used) + " of " +
                     std::to_string(listed) + " " + std::string(ToString(kind)) +
                     " views usable, at least " + std::to_string(minimum) + " are needed (" +
                     WhyMinimum(kind) + "); dropped:";
  std::string separator = " ";
  for (const DroppedView& d : out_.dropped_views) {
    if (d.kind != kind) continue;
    text += separator + ViewName(d.image, d.kind, d.index, d.z_mm) + ": " + d.reason;
    separator = "; ";
  }
  Throw(CalibrationErrorReason::kNotFound, text);
}

// A stage's CalibrationError again, its message prefixed with the manifest.
void SideCalibrationRun::Rethrow(const CalibrationError& e) const {
  Throw(e.reason(), "calibration: " + file_ + ": " + e.what());
}

// 1. Thesis 6.1: target squares' centres of gravity in every camera view,
// then Tsai's two-stage calibration on the views whose grid was found.
void SideCalibrationRun::CalibrateCameraViews() {
  std::vector<TargetView> views;
  for (size_t i = 0; i < manifest_.camera_views.size(); ++i) {
    const ManifestView& view = manifest_.camera_views[i];
    const std::string name = ViewName(view, ViewKind::kCamera, i);
    BeginView(name);
    const cv::Mat grey = Load(view, name);
    const TargetDetection detection = DetectTarget(grey, manifest_.target, params_.target);
    if (!detection.ok) {
      Drop(view, ViewKind::kCamera, i, "target not found: " + detection.error);
      continue;
    }
    TargetView target_view;
    for (const TargetSquare& square : detection.squares) {
      TargetPoint point;
      point.world_mm = manifest_.target.SquareCentre(square.row, square.col, view.z_mm);
      point.image_px = {square.centre.x, square.centre.y};
      target_view.points.push_back(point);
    }
    views.push_back(std::move(target_view));
    CameraViewReport report;
    report.image = view.image;
    report.z_mm = view.z_mm;
    report.max_grid_residual = detection.max_grid_residual;
    out_.camera_views.push_back(report);
  }
  Require(ViewKind::kCamera, views.size(), manifest_.camera_views.size(), params_.min_camera_views);
  out_.width = width_;
  out_.height = height_;
  try {
    out_.camera = CalibrateCamera(views, width_, height_, params_.camera);
  } catch (const CalibrationError& e) {
    Rethrow(e);
  }
  if (!out_.camera.report.converged)
    Throw(CalibrationErrorReason::kNotConverged,
          "calibration: " + file_ + ": camera calibration did not converge in " +
              std::to_string(out_.camera.report.iterations) + " iterations (RMS " +
              Number(out_.camera.report.rms_px) + " px)");
  for (size_t i = 0; i < out_.camera_views.size(); ++i) {
    out_.camera_views[i].rms_px = out_.camera.report.view_rms_px[i];
    out_.camera_views[i].rms_mm = out_.camera.report.view_rms_mm[i];
  }
  out_.sigmas.target_point_px = out_.camera.report.residual_sigma_px;
}

// The report of one decoded screen view, its line-centre samples
// back-projected onto its screen appended to `points` and its centre scatter
// to `sum2` and `dof`; nothing (the view dropped) when no sample lands.
std::optional<ScreenViewReport> SideCalibrationRun::ScreenStripePoints(
    const ManifestView& view, size_t index, const decoder::DecodeResult& result,
    std::vector<StripePoint>* points, double* sum2, double* dof) {
  const geometry::PinholeModel& camera = out_.camera.model;
  ScreenViewReport report;
  report.image = view.image;
  report.z_mm = view.z_mm;
  report.lines = static_cast<int>(result.lines.size());
  report.junctions = static_cast<int>(result.junctions.size());
  for (const decoder::DecodedLine& line : result.lines) {
    AccumulateCentreScatter(line.points, params_.centre_fit_degree, params_.min_centre_run, sum2,
                            dof);
    for (size_t k = 0; k < line.points.size(); k += params_.stripe_sample_step) {
      const Eigen::Vector2d image(line.points[k].x, line.points[k].y);
      const auto world = internal::IntersectZPlane(camera.BackProject(image), view.z_mm);
      if (world) points->push_back({*world, line.p});
    }
  }
  if (points->empty()) {
    Drop(view, ViewKind::kScreen, index,
         "no decoded line-centre sample back-projects onto the screen (" +
             std::to_string(report.lines) + " lines decoded)");
    return std::nullopt;
  }
  report.stripe_points = static_cast<int>(points->size());
  return report;
}

// 2. Thesis 6.2: decode every screen view; back-project each labelled
// line-centre sample onto its screen.
std::vector<decoder::DecodeResult> SideCalibrationRun::DecodeScreenViews() {
  decoder::DecodeParams decode = params_.decode;
  decode.spec = manifest_.pattern;
  std::vector<decoder::DecodeResult> decoded;  // one per used screen view
  double centre_sum2 = 0.0, centre_dof = 0.0;
  for (size_t i = 0; i < manifest_.screen_views.size(); ++i) {
    const ManifestView& view = manifest_.screen_views[i];
    const std::string name = ViewName(view, ViewKind::kScreen, i);
    BeginView(name);
    const cv::Mat grey = Load(view, name);
    decoder::DecodeResult result = decoder::Decode(grey, manifest_.side, decode, cancel_);
    if (!result.ok) {
      Drop(view, ViewKind::kScreen, i, "the brick pattern could not be decoded: " + result.error);
      continue;
    }
    std::vector<StripePoint> points;
    double sum2 = 0.0, dof = 0.0;
    const std::optional<ScreenViewReport> report =
        ScreenStripePoints(view, i, result, &points, &sum2, &dof);
    if (!report) continue;
    centre_sum2 += sum2;
    centre_dof += dof;
    view_begin_.push_back(out_.diagnostics.stripe_points.size());
    out_.diagnostics.stripe_points.insert(out_.diagnostics.stripe_points.end(), points.begin(),
                                          points.end());
    out_.screen_views.push_back(*report);
    decoded.push_back(std::move(result));
  }
  Require(ViewKind::kScreen, out_.screen_views.size(), manifest_.screen_views.size(),
          params_.min_screen_views);
  view_begin_.push_back(out_.diagnostics.stripe_points.size());
  out_.sigmas.stripe_centre_px = centre_dof > 0.0 ? std::sqrt(centre_sum2 / centre_dof) : 0.0;
  return decoded;
}

// 3. Thesis 6.2.1 and 6.2.2, each with its two-pass outlier rejection.
void SideCalibrationRun::FitStripePlanes() {
  try {
    out_.parallel = FitParallelPlaneModel(out_.diagnostics.stripe_points, params_.stripes);
    out_.perspective = FitPerspectivePlaneModel(out_.diagnostics.stripe_points, params_.stripes);
  } catch (const CalibrationError& e) {
    Rethrow(e);
  }
  out_.sigmas.plane_mm = out_.perspective.report.rms_mm;
  for (size_t i = 0; i < out_.screen_views.size(); ++i) {
    double sum2 = 0.0;
    int count = 0;
    for (size_t k = view_begin_[i]; k < view_begin_[i + 1]; ++k) {
      if (!out_.perspective.report.inlier[k]) continue;
      const StripePoint& point = out_.diagnostics.stripe_points[k];
      const double d =
          out_.perspective.model.PlaneOfLine(point.line).SignedDistance(point.world_mm);
      sum2 += d * d;
      ++count;
    }
    out_.screen_views[i].plane_rms_mm = count > 0 ? std::sqrt(sum2 / count) : 0.0;
  }
}

// The centre of the cross in every reference view, on its screen; views
// whose cross is not found or whose centre misses the screen dropped.
void SideCalibrationRun::FindCrosses() {
  const geometry::PinholeModel& camera = out_.camera.model;
  for (size_t i = 0; i < manifest_.reference_views.size(); ++i) {
    const ManifestView& view = manifest_.reference_views[i];
    const std::string name = ViewName(view, ViewKind::kReference, i);
    BeginView(name);
    const cv::Mat grey = Load(view, name);
    std::string cross_why;
    const auto cross = FindReferenceCross(grey, params_.cross, &cross_why);
    if (!cross) {
      Drop(view, ViewKind::kReference, i, "reference cross not found: " + cross_why);
      continue;
    }
    ReferenceViewReport report;
    report.image = view.image;
    report.z_mm = view.z_mm;
    report.centre_px = {cross->centre.x, cross->centre.y};
    const auto world = internal::IntersectZPlane(camera.BackProject(report.centre_px), view.z_mm);
    if (!world) {
      Drop(view, ViewKind::kReference, i, "the camera ray of the cross centre misses the screen");
      continue;
    }
    report.world_mm = *world;
    out_.reference_views.push_back(report);
    cross_index_.push_back(i);
  }
}

// Drops crosses off the line through the others until the rest lie on one
// within params.max_reference_ray_residual_mm; throws when that cannot be
// told.
void SideCalibrationRun::RejectOffRayCrosses() {
  // A centre off the line through the others is a misread cross or a wrong
  // z. It can be told from the rest only when at least three others remain
  // to agree on a line; it is the one whose removal leaves them on one.
  const double limit = params_.max_reference_ray_residual_mm;
  for (;;) {
    std::vector<ReferenceViewReport>& crosses = out_.reference_views;
    std::vector<Eigen::Vector3d> centres;
    for (const auto& r : crosses) centres.push_back(r.world_mm);
    if (crosses.size() < 3 || WorstOffRay(centres) <= limit) break;
    // Each cross against the line through the others.
    std::vector<double> off(crosses.size()), rest(crosses.size());
    for (size_t k = 0; k < crosses.size(); ++k) {
      const std::vector<Eigen::Vector3d> others = AllBut(crosses, k);
      off[k] = DistanceToLine(FitRay(others), crosses[k].world_mm);
      rest[k] = WorstOffRay(others);
    }
    const size_t worst = std::max_element(off.begin(), off.end()) - off.begin();
    const size_t best = std::min_element(rest.begin(), rest.end()) - rest.begin();
    const std::string off_text = "the cross centre lies " + Number(off[best]) +
                                 " mm off the line through the other cross centres (limit " +
                                 Number(limit) + " mm): a misread cross or a wrong z_mm";
    if (crosses.size() < 4 || rest[best] > limit) {
      const size_t named = crosses.size() < 4 ? worst : best;
      Throw(CalibrationErrorReason::kInvalidInput,
            "calibration: " +
                ViewName(manifest_.reference_views[cross_index_[named]], ViewKind::kReference,
                         cross_index_[named]) +
                ": the cross centre lies " + Number(off[named]) +
                " mm off the line through the other cross centres (limit " + Number(limit) +
                " mm): a misread cross or a wrong z_mm; with " + std::to_string(crosses.size()) +
                " crosses, " +
                (crosses.size() < 4 ? "fewer than three others cannot tell which is wrong"
                                    : "no three of them agree on a line"));
    }
    Drop(manifest_.reference_views[cross_index_[best]], ViewKind::kReference, cross_index_[best],
         off_text);
    crosses.erase(crosses.begin() + static_cast<std::ptrdiff_t>(best));
    cross_index_.erase(cross_index_.begin() + static_cast<std::ptrdiff_t>(best));
  }
}

// The q offset of each screen view: the image of slide point (0, 0) on its
// plane, where the reference ray meets it.
void SideCalibrationRun::SetQOffsets(const std::vector<decoder::DecodeResult>& decoded) {
  const geometry::PinholeModel& camera = out_.camera.model;
  for (size_t i = 0; i < out_.screen_views.size() && out_.reference_ray; ++i) {
    ScreenViewReport& report = out_.screen_views[i];
    const std::optional<Eigen::Vector3d> origin = out_.reference_ray->AtZ(report.z_mm);
    if (!origin) continue;
    const auto image = camera.Project(*origin);
    if (!image) continue;
    const decoder::DecodedJunction* nearest = nullptr;
    double best = params_.max_origin_junction_px;
    for (const decoder::DecodedJunction& j : decoded[i].junctions) {
      if (j.p != 0) continue;
      const double d = std::hypot(j.position.x - image->x(), j.position.y - image->y());
      if (d <= best) {
        best = d;
        nearest = &j;
      }
    }
    // Line-0 junctions sit on even rows only, so the offset is even.
    if (nearest) report.q_offset = -nearest->q;
  }
}

// 4. Slide 1: the cross centre is slide point (0, 0) = brick line 0, row 0.
void SideCalibrationRun::FixSlideRows(const std::vector<decoder::DecodeResult>& decoded) {
  FindCrosses();
  if (!manifest_.reference_views.empty()) {
    Require(ViewKind::kReference, out_.reference_views.size(), manifest_.reference_views.size(),
            params_.min_reference_views);
    RejectOffRayCrosses();
    std::vector<Eigen::Vector3d> centres;
    for (const auto& r : out_.reference_views) centres.push_back(r.world_mm);
    out_.reference_ray = FitRay(centres);
    for (ReferenceViewReport& r : out_.reference_views)
      r.ray_residual_mm = DistanceToLine(*out_.reference_ray, r.world_mm);
  }
  SetQOffsets(decoded);
}

// The junctions of the screen views with a q offset, on their screens, with
// their absolute slide points, appended to diagnostics.junction_points;
// returns the first junction point of each used screen view, then the end.
std::vector<size_t> SideCalibrationRun::CollectJunctionPoints(
    const std::vector<decoder::DecodeResult>& decoded) {
  const geometry::PinholeModel& camera = out_.camera.model;
  std::vector<size_t> junction_begin;  // first junction point of each used screen view
  for (size_t i = 0; i < out_.screen_views.size(); ++i) {
    ScreenViewReport& report = out_.screen_views[i];
    junction_begin.push_back(out_.diagnostics.junction_points.size());
    if (!report.q_offset) continue;
    for (const decoder::DecodedJunction& j : decoded[i].junctions) {
      if (j.interpolated && !params_.use_interpolated_junctions) continue;
      const auto world =
          internal::IntersectZPlane(camera.BackProject({j.position.x, j.position.y}), report.z_mm);
      if (!world) continue;
      out_.diagnostics.junction_points.push_back(
          {*world, SlideOfJunction(manifest_.side, j.p, j.q + *report.q_offset)});
      ++report.matrix_junctions;
    }
  }
  junction_begin.push_back(out_.diagnostics.junction_points.size());
  return junction_begin;
}

// 5. Thesis eq. 2.16: the projector matrix from the junctions of the views
// whose rows are absolute (decoder::DecodeParams::q_offset added, as the
// decoder would).
void SideCalibrationRun::FitMatrix(const std::vector<decoder::DecodeResult>& decoded) {
  const std::vector<size_t> junction_begin = CollectJunctionPoints(decoded);
  if (manifest_.reference_views.empty()) return;
  if (out_.diagnostics.junction_points.empty())
    Throw(CalibrationErrorReason::kNotFound,
          "calibration: " + file_ + ": no screen view's line-0 junction lies within " +
              Number(params_.max_origin_junction_px) +
              " px of the reference ray's image: the slide rows cannot be fixed");
  try {
    out_.projector_matrix = FitProjectorMatrix(out_.diagnostics.junction_points, params_.matrix);
  } catch (const CalibrationError& e) {
    Rethrow(e);
  }
  if (!out_.projector_matrix->report.converged)
    Throw(CalibrationErrorReason::kNotConverged,
          "calibration: " + file_ + ": projector matrix did not converge in " +
              std::to_string(out_.projector_matrix->report.iterations) + " iterations");
  const ProjectorMatrixFit& matrix = *out_.projector_matrix;
  for (size_t i = 0; i < out_.screen_views.size(); ++i) {
    double sum2 = 0.0;
    int count = 0;
    for (size_t k = junction_begin[i]; k < junction_begin[i + 1]; ++k) {
      if (!matrix.report.inlier[k]) continue;
      const JunctionPoint& j = out_.diagnostics.junction_points[k];
      const auto slide = matrix.model.Project(j.world_mm);
      if (!slide) continue;
      sum2 += (*slide - j.slide_st).squaredNorm();
      ++count;
    }
    if (count > 0) out_.screen_views[i].matrix_rms_d = std::sqrt(sum2 / count);
  }
}

}  // namespace

bool SideCalibrationParams::IsValid(std::string* error) const {
  std::string why;
  if (!target.IsValid(&why)) return Fail(error, "target detection: " + why);
  if (!camera.IsValid(&why)) return Fail(error, "camera: " + why);
  if (!decode.IsValid(&why)) return Fail(error, "decode: " + why);
  if (decode.q_offset) return Fail(error, "decode.q_offset must be unset (the crosses set it)");
  if (!stripes.IsValid(&why)) return Fail(error, "stripes: " + why);
  if (!cross.IsValid(&why)) return Fail(error, "cross: " + why);
  if (!matrix.IsValid(&why)) return Fail(error, "matrix: " + why);
  if (min_camera_views < 2) return Fail(error, "min_camera_views must be at least 2");
  if (min_screen_views < 2) return Fail(error, "min_screen_views must be at least 2");
  if (min_reference_views < 2) return Fail(error, "min_reference_views must be at least 2");
  if (stripe_sample_step < 1) return Fail(error, "stripe_sample_step must be at least 1");
  if (!(max_origin_junction_px > 0.0))
    return Fail(error, "max_origin_junction_px must be positive");
  if (!(max_reference_ray_residual_mm > 0.0))
    return Fail(error, "max_reference_ray_residual_mm must be positive");
  if (centre_fit_degree < 1 || centre_fit_degree > 5)
    return Fail(error, "centre_fit_degree must lie in 1..5");
  if (min_centre_run <= centre_fit_degree + 1)
    return Fail(error, "min_centre_run must exceed centre_fit_degree + 1");
  return true;
}

std::string_view ToString(ViewKind kind) {
  switch (kind) {
    case ViewKind::kCamera:
      return "camera";
    case ViewKind::kScreen:
      return "screen";
    case ViewKind::kReference:
      return "reference";
  }
  return "unknown";
}

std::optional<Eigen::Vector3d> ReferenceRay::AtZ(double z_mm) const {
  if (std::abs(direction.z()) < 1e-12) return std::nullopt;
  return point_mm + ((z_mm - point_mm.z()) / direction.z()) * direction;
}

ProjectorPose PoseOfProjector(const PerspectivePlaneFit& perspective,
                              const std::optional<ProjectorMatrixFit>& matrix,
                              const geometry::PinholeModel& camera) {
  ProjectorPose pose;
  pose.plane_centre_mm = perspective.model.centre_mm;
  pose.plane_axis = perspective.model.axis_direction;
  pose.plane_centre_distance_mm = perspective.model.centre_mm.norm();
  if (matrix) {
    const Eigen::Vector3d centre = matrix->model.Centre();
    // Device z (the viewing direction) in world coordinates.
    const Eigen::Vector3d axis = matrix->model.pose().rotation.row(2).transpose().normalized();
    pose.matrix_centre_mm = centre;
    pose.optical_axis = axis;
    pose.matrix_centre_distance_mm = centre.norm();
    const Eigen::Vector3d camera_axis = camera.pose().rotation.row(2).transpose().normalized();
    pose.camera_projector_angle_deg =
        std::acos(std::clamp(camera_axis.dot(axis), -1.0, 1.0)) * 180.0 / M_PI;
  }
  return pose;
}

// Thesis chapter 6 (6.1 camera, 6.2 projector) for one side of the rig.
SideCalibration CalibrateSide(const Manifest& manifest, const SideCalibrationParams& params,
                              const CalibrationProgress& progress, const Cancellation& cancel) {
  const auto start = Clock::now();
  SideCalibrationRun run(manifest, params, progress, cancel);
  run.CheckInputs();

  SideCalibration& out = run.out();
  out.side = manifest.side;
  out.manifest_sha256 = manifest.sha256;
  out.pattern = manifest.pattern;
  out.target = manifest.target;

  // 1. Thesis 6.1: camera.
  auto t = Clock::now();
  run.CalibrateCameraViews();
  out.diagnostics.times.camera_ms = MsSince(t);
  const geometry::PinholeModel& camera = out.camera.model;

  // 2. Thesis 6.2: stripe points of the screen views.
  t = Clock::now();
  const std::vector<decoder::DecodeResult> decoded = run.DecodeScreenViews();
  out.diagnostics.times.stripes_ms = MsSince(t);

  // 3. Thesis 6.2.1 and 6.2.2: the light planes.
  t = Clock::now();
  run.FitStripePlanes();
  out.diagnostics.times.planes_ms = MsSince(t);

  // 4. and 5.: slide rows from the reference crosses, then the projector
  // matrix (thesis eq. 2.16).
  t = Clock::now();
  run.FixSlideRows(decoded);
  run.FitMatrix(decoded);
  std::stable_sort(out.dropped_views.begin(), out.dropped_views.end(),
                   [](const DroppedView& a, const DroppedView& b) {
                     return std::tie(a.kind, a.index) < std::tie(b.kind, b.index);
                   });
  out.projector = PoseOfProjector(out.perspective, out.projector_matrix, camera);
  out.diagnostics.times.reference_ms = MsSince(t);
  out.diagnostics.times.total_ms = MsSince(start);
  return std::move(out);
}

bool SharesWorldFrame(const SideCalibration& left, const SideCalibration& right, std::string* why,
                      double tolerance_mm) {
  const auto fail = [why](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  const auto mm = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f mm", v);
    return std::string(text);
  };
  if (left.side == right.side) return fail("both calibrations are of the same side");
  const TargetGeometry& a = left.target;
  const TargetGeometry& b = right.target;
  if (a.rows != b.rows || a.cols != b.cols || a.pitch_mm != b.pitch_mm ||
      a.square_mm != b.square_mm)
    return fail("the two calibrations used different targets");
  const bool matrices = left.projector.matrix_centre_mm && right.projector.matrix_centre_mm;
  const Eigen::Vector3d pa =
      matrices ? *left.projector.matrix_centre_mm : left.projector.plane_centre_mm;
  const Eigen::Vector3d pb =
      matrices ? *right.projector.matrix_centre_mm : right.projector.plane_centre_mm;
  const double centres = (pa - pb).norm();
  if (!(centres <= tolerance_mm))
    return fail("the projector centres of the two calibrations are " + mm(centres) + " apart");
  if (left.reference_ray && right.reference_ray) {
    const double rays = (left.reference_ray->point_mm - right.reference_ray->point_mm).norm();
    if (!(rays <= tolerance_mm))
      return fail("the reference rays of the two calibrations meet z = 0 " + mm(rays) + " apart");
  }
  return true;
}

}  // namespace bsls::calibration
