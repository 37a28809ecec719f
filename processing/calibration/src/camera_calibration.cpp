#include "bsls/calibration/camera_calibration.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "pinhole_refinement.h"
#include "point_set_geometry.h"

namespace bsls::calibration {
namespace {

[[noreturn]] void Throw(CalibrationErrorReason reason, const std::string& message) {
  throw CalibrationError(reason, message);
}

void CheckCorrespondences(const char* stage, const std::vector<Eigen::Vector3d>& world,
                          const std::vector<Eigen::Vector2d>& image, size_t min_points) {
  if (world.size() != image.size()) {
    std::ostringstream os;
    os << stage << ": " << world.size() << " world points but " << image.size() << " image points";
    Throw(CalibrationErrorReason::kInvalidInput, os.str());
  }
  if (world.size() < min_points) {
    std::ostringstream os;
    os << stage << ": " << world.size() << " points; at least " << min_points << " are needed";
    Throw(CalibrationErrorReason::kTooFewPoints, os.str());
  }
  for (size_t i = 0; i < world.size(); ++i) {
    if (!world[i].allFinite() || !image[i].allFinite()) {
      std::ostringstream os;
      os << stage << ": point " << i << " has a non-finite coordinate";
      Throw(CalibrationErrorReason::kInvalidInput, os.str());
    }
  }
}

// Decomposes C (3x4, det of its left block made positive) into K [R | t].
void Decompose(DltSolution* dlt) {
  Matrix34d c = dlt->matrix;
  if (c.leftCols<3>().determinant() < 0.0) c = -c;
  c /= c.block<1, 3>(2, 0).norm();
  const Eigen::Matrix3d m = c.leftCols<3>();
  // RQ decomposition through QR of the row-reversed transpose.
  Eigen::Matrix3d flip;
  flip << 0, 0, 1, 0, 1, 0, 1, 0, 0;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((flip * m).transpose());
  const Eigen::Matrix3d q = qr.householderQ();
  const Eigen::Matrix3d r = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d k = flip * r.transpose() * flip;
  Eigen::Matrix3d rotation = flip * q.transpose();
  const Eigen::Vector3d signs(k(0, 0) < 0 ? -1.0 : 1.0, k(1, 1) < 0 ? -1.0 : 1.0,
                              k(2, 2) < 0 ? -1.0 : 1.0);
  k = k * signs.asDiagonal();
  rotation = signs.asDiagonal() * rotation;
  dlt->translation = k.triangularView<Eigen::Upper>().solve(c.col(3));
  dlt->k = k / k(2, 2);
  dlt->rotation = rotation;
  dlt->matrix = c;
}

double RmsOf(const std::vector<double>& errors) {
  if (errors.empty()) return 0.0;
  double sum = 0.0;
  for (double e : errors) sum += e * e;
  return std::sqrt(sum / static_cast<double>(errors.size()));
}

double MaxOf(const std::vector<double>& errors) {
  double m = 0.0;
  for (double e : errors) m = std::max(m, e);
  return m;
}

// The rotation, x and y translation and scale factor sx of the radial
// alignment constraint, with world points taken about `centroid`.
struct RacSolution {
  Eigen::Matrix3d rotation;
  double tx = 0.0;
  double ty = 0.0;
  double sx = 0.0;
};

// Thesis 6.1 (Tsai's first stage): solves the RAC for R, tx, ty and sx,
// throwing kDegenerate when the points do not determine them.
RacSolution SolveRac(const char* stage, const std::vector<Eigen::Vector3d>& world_mm,
                     const std::vector<Eigen::Vector2d>& image_px,
                     const Eigen::Vector2d& principal_point_px, const Eigen::Vector3d& centroid) {
  // RAC: (u - cx) * yc = sx * (v - cy) * xc with xc = r1.X + tx, yc = r2.X + ty,
  // linear and homogeneous in L = (sx r1, sx tx, r2, ty). World points are
  // taken relative to their centroid (translation t' = t + R centroid).
  const auto n = static_cast<Eigen::Index>(world_mm.size());
  Eigen::MatrixXd a(n, 8);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto iu = static_cast<size_t>(i);
    const Eigen::Vector3d x = world_mm[iu] - centroid;
    const double xd = image_px[iu].x() - principal_point_px.x();
    const double yd = image_px[iu].y() - principal_point_px.y();
    a.block<1, 3>(i, 0) = -yd * x.transpose();
    a(i, 3) = -yd;
    a.block<1, 3>(i, 4) = xd * x.transpose();
    a(i, 7) = xd;
  }
  const Eigen::VectorXd column_norms = a.colwise().norm().transpose();
  if ((column_norms.array() <= 0.0).any()) {
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(stage) + ": every point lies on a principal image row or column");
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a * column_norms.cwiseInverse().asDiagonal(),
                                              Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  if (s(6) <= 1e-9 * s(0)) {
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(stage) + ": the solution is not unique (more than one null vector)");
  }
  Eigen::Matrix<double, 8, 1> l = column_norms.cwiseInverse().asDiagonal() * svd.matrixV().col(7);
  const double r2_norm = l.segment<3>(4).norm();
  if (!(r2_norm > 0.0)) Throw(CalibrationErrorReason::kDegenerate, std::string(stage) + ": r2 = 0");
  l /= r2_norm;
  const double sx = l.head<3>().norm();
  if (!(sx > 0.0)) Throw(CalibrationErrorReason::kDegenerate, std::string(stage) + ": sx = 0");
  Eigen::Vector3d r1 = l.head<3>() / sx;
  double tx = l(3) / sx;
  Eigen::Vector3d r2 = l.segment<3>(4);
  double ty = l(7);
  // Sign of ty (Tsai): the camera-frame x, y of a point share the signs of its
  // image offsets from the principal point; vote over all points.
  double agreement = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto iu = static_cast<size_t>(i);
    const Eigen::Vector3d x = world_mm[iu] - centroid;
    agreement += (image_px[iu].x() - principal_point_px.x()) * (r1.dot(x) + tx) +
                 (image_px[iu].y() - principal_point_px.y()) * (r2.dot(x) + ty);
  }
  if (agreement < 0.0) {
    r1 = -r1;
    r2 = -r2;
    tx = -tx;
    ty = -ty;
  }
  Eigen::Matrix3d r;
  r.row(0) = r1.transpose();
  r.row(1) = r2.transpose();
  r.row(2) = r1.cross(r2).transpose();
  RacSolution out;
  out.rotation = internal::NearestRotation(r);
  out.tx = tx;
  out.ty = ty;
  out.sx = sx;
  return out;
}

// Tsai's second stage without distortion: (f, tz) by least squares, throwing
// kDegenerate when they are undetermined or f is not positive.
Eigen::Vector2d SolveFocalAndTz(const char* stage, const std::vector<Eigen::Vector3d>& world_mm,
                                const std::vector<Eigen::Vector2d>& image_px,
                                const Eigen::Vector2d& principal_point_px,
                                const Eigen::Vector3d& centroid, const RacSolution& rac) {
  // f and tz from both image axes, distortion taken as 0:
  //   (v - cy)(r3.X + tz) = f yc,   (u - cx)(r3.X + tz) = sx f xc.
  const Eigen::Matrix3d& r = rac.rotation;
  const auto n = static_cast<Eigen::Index>(world_mm.size());
  Eigen::MatrixXd m(2 * n, 2);
  Eigen::VectorXd rhs(2 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto iu = static_cast<size_t>(i);
    const Eigen::Vector3d x = world_mm[iu] - centroid;
    const double xd = image_px[iu].x() - principal_point_px.x();
    const double yd = image_px[iu].y() - principal_point_px.y();
    const double xc = r.row(0).dot(x) + rac.tx;
    const double yc = r.row(1).dot(x) + rac.ty;
    const double w = r.row(2).dot(x);
    m.row(2 * i) << yc, -yd;
    rhs(2 * i) = yd * w;
    m.row(2 * i + 1) << rac.sx * xc, -xd;
    rhs(2 * i + 1) = xd * w;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(m);
  if (qr.rank() < 2)
    Throw(CalibrationErrorReason::kDegenerate, std::string(stage) + ": f and tz undetermined");
  const Eigen::Vector2d ftz = qr.solve(rhs);
  if (!(ftz(0) > 0.0)) {
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(stage) +
              ": the focal length comes out negative; the image or world axes are mirrored");
  }
  return ftz;
}

// The target points of all views pooled, with the view each came from;
// throws kInvalidInput on a non-finite coordinate.
struct PooledPoints {
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Vector2d> image;
  std::vector<size_t> view_of;
};

PooledPoints PoolViews(const char* stage, const std::vector<TargetView>& views) {
  PooledPoints pooled;
  for (size_t v = 0; v < views.size(); ++v) {
    for (size_t i = 0; i < views[v].points.size(); ++i) {
      const TargetPoint& p = views[v].points[i];
      if (!p.world_mm.allFinite() || !p.image_px.allFinite()) {
        std::ostringstream os;
        os << stage << ": view " << v << " point " << i << " has a non-finite coordinate";
        Throw(CalibrationErrorReason::kInvalidInput, os.str());
      }
      pooled.world.push_back(p.world_mm);
      pooled.image.push_back(p.image_px);
      pooled.view_of.push_back(v);
    }
  }
  return pooled;
}

// Throws unless there are enough points and they leave one plane by at least
// params.min_out_of_plane_mm.
void CheckPointSpread(const char* stage, const std::vector<Eigen::Vector3d>& world,
                      size_t num_views, const CameraCalibrationParams& params) {
  if (world.size() < static_cast<size_t>(kMinCalibrationPoints)) {
    std::ostringstream os;
    os << stage << ": " << world.size() << " points in " << num_views << " views; at least "
       << kMinCalibrationPoints << " are needed";
    Throw(CalibrationErrorReason::kTooFewPoints, os.str());
  }
  const double off_plane = internal::OutOfPlaneRms(world);
  if (off_plane < params.min_out_of_plane_mm) {
    std::ostringstream os;
    os << stage << ": all " << world.size() << " points lie in one plane (RMS " << off_plane
       << " mm off their best-fitting plane, limit " << params.min_out_of_plane_mm
       << " mm); the non-coplanar calibration needs target views at two or more z offsets";
    Throw(CalibrationErrorReason::kCoplanar, os.str());
  }
}

using StartingModels = std::vector<std::pair<CameraInitialisation, geometry::PinholeModel>>;

// Starting models: Tsai's (the thesis method) and the DLT's, in that order;
// Tsai's only when its linear stage succeeded.
StartingModels StartsOf(const CameraCalibrationReport& report,
                        const CameraCalibrationParams& params, const Eigen::Vector2d& principal) {
  StartingModels starts;
  if (report.tsai) {
    geometry::Intrinsics in;
    in.fy = report.tsai->f_px;
    in.fx = params.refine_scale_factor ? report.tsai->sx * report.tsai->f_px : in.fy;
    in.cx = principal.x();
    in.cy = principal.y();
    in.k1 = in.k2 = 0.0;
    starts.emplace_back(CameraInitialisation::kTsai,
                        geometry::PinholeModel(
                            in, geometry::Pose{report.tsai->rotation, report.tsai->translation}));
  }
  {
    const Eigen::Matrix3d& k = report.dlt.k;
    geometry::Intrinsics in;
    in.fy = k(1, 1);
    in.fx = params.refine_scale_factor ? k(0, 0) : k(1, 1);
    in.cx = params.refine_principal_point ? k(0, 2) : principal.x();
    in.cy = params.refine_principal_point ? k(1, 2) : principal.y();
    in.k1 = in.k2 = 0.0;
    starts.emplace_back(
        CameraInitialisation::kDlt,
        geometry::PinholeModel(in, geometry::Pose{report.dlt.rotation, report.dlt.translation}));
  }
  return starts;
}

// Which pinhole parameters the refinement may move, from the params' switches.
std::array<bool, internal::kPinholeParamCount> FreeParameters(
    const CameraCalibrationParams& params) {
  std::array<bool, internal::kPinholeParamCount> free{};
  free.fill(true);
  free[internal::kFocalB] = params.refine_scale_factor;
  free[internal::kCx] = free[internal::kCy] = params.refine_principal_point;
  free[internal::kK1] = params.refine_k1;
  free[internal::kK2] = params.refine_k2;
  return free;
}

// Refines every start and keeps the lowest (Tsai's unless the DLT's ends
// clearly lower), setting report.initialisation; nothing when none refines
// to a usable camera, each failure then appended to `failures`.
std::optional<internal::PinholeRefinement> RefineBest(const PooledPoints& points,
                                                      const StartingModels& starts,
                                                      const CameraCalibrationParams& params,
                                                      CameraCalibrationReport& report,
                                                      std::string* failures) {
  const std::array<bool, internal::kPinholeParamCount> free = FreeParameters(params);
  internal::LmOptions options;
  options.max_iterations = params.max_iterations;

  std::optional<internal::PinholeRefinement> best;
  for (const auto& [kind, start] : starts) {
    const char* name = kind == CameraInitialisation::kTsai ? "Tsai" : "DLT";
    auto refined = internal::RefinePinhole(points.world, points.image, start,
                                           internal::FocalForm::kFSx, free, options);
    if (!refined) {
      *failures += std::string(" (") + name + " start: points behind the camera)";
      continue;
    }
    std::string invalid;
    if (!refined->model.intrinsics().IsValid(&invalid)) {
      *failures += std::string(" (") + name + " start: refined to " + invalid + ")";
      continue;
    }
    // Tsai's start comes first and is kept unless the DLT's ends clearly lower.
    constexpr double kClearlyLower = 1.0 - 1e-6;
    if (!best || refined->residuals.squaredNorm() < kClearlyLower * best->residuals.squaredNorm()) {
      best = std::move(refined);
      report.initialisation = kind;
    }
  }
  return best;
}

// Standard deviations of the reported parameters from the refinement's
// covariance; report.f_px and report.sx must already be set.
CameraParameterSigmas SigmasOf(const internal::PinholeMatrix& c,
                               const CameraCalibrationReport& report) {
  auto sd = [&c](int i) { return std::sqrt(std::max(c(i, i), 0.0)); };
  CameraParameterSigmas s;
  s.f_px = sd(internal::kFocalA);
  s.sx = sd(internal::kFocalB);
  s.fy_px = s.f_px;
  const double var_fx = report.sx * report.sx * c(internal::kFocalA, internal::kFocalA) +
                        report.f_px * report.f_px * c(internal::kFocalB, internal::kFocalB) +
                        2.0 * report.sx * report.f_px * c(internal::kFocalA, internal::kFocalB);
  s.fx_px = std::sqrt(std::max(var_fx, 0.0));
  s.cx_px = sd(internal::kCx);
  s.cy_px = sd(internal::kCy);
  s.k1 = sd(internal::kK1);
  s.k2 = sd(internal::kK2);
  for (int j = 0; j < 3; ++j) {
    s.rotation_rad(j) = sd(internal::kWx + j);
    s.translation_mm(j) = sd(internal::kTx + j);
  }
  return s;
}

// Fills the report's RMS and maximum errors, overall and per view.
void ReportResiduals(const PooledPoints& points, size_t num_views,
                     const geometry::PinholeModel& model, CameraCalibrationReport& report) {
  // Errors in pixels and, on each point's own z plane, in millimetres.
  const std::vector<Eigen::Vector3d>& world = points.world;
  const std::vector<Eigen::Vector2d>& image = points.image;
  std::vector<double> px_errors(world.size());
  std::vector<double> mm_errors(world.size());
  std::vector<std::vector<double>> view_px(num_views);
  std::vector<std::vector<double>> view_mm(num_views);
  for (size_t i = 0; i < world.size(); ++i) {
    const auto projected = model.Project(world[i]);
    px_errors[i] = projected ? (*projected - image[i]).norm() : HUGE_VAL;
    const geometry::Ray ray = model.BackProject(image[i]);
    const auto on_plane = internal::IntersectZPlane(ray, world[i].z());
    mm_errors[i] = on_plane ? (*on_plane - world[i]).norm() : HUGE_VAL;
    view_px[points.view_of[i]].push_back(px_errors[i]);
    view_mm[points.view_of[i]].push_back(mm_errors[i]);
  }
  report.rms_px = RmsOf(px_errors);
  report.max_px = MaxOf(px_errors);
  report.rms_mm = RmsOf(mm_errors);
  report.max_mm = MaxOf(mm_errors);
  for (size_t v = 0; v < num_views; ++v) {
    report.view_rms_px.push_back(RmsOf(view_px[v]));
    report.view_rms_mm.push_back(RmsOf(view_mm[v]));
  }
}

}  // namespace

bool CameraCalibrationParams::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (principal_point_px && !principal_point_px->allFinite())
    return fail("principal_point_px must be finite");
  if (!(min_out_of_plane_mm >= 0.0) || !std::isfinite(min_out_of_plane_mm))
    return fail("min_out_of_plane_mm must be finite and >= 0");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  return true;
}

// Thesis 2.3, eq. 2.19.
DltSolution SolveDlt(const std::vector<Eigen::Vector3d>& world_mm,
                     const std::vector<Eigen::Vector2d>& image_px) {
  constexpr const char* kStage = "linear camera matrix (DLT)";
  CheckCorrespondences(kStage, world_mm, image_px, 6);
  const internal::Similarity3 tw = internal::NormalisingSimilarity(world_mm);
  const internal::Similarity2 ti = internal::NormalisingSimilarity(image_px);
  if (tw.scale <= 0.0 || ti.scale <= 0.0)
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(kStage) + ": all points coincide in the world or in the image");
  if (internal::OutOfPlaneRms(world_mm) <= 1e-9 / tw.scale) {
    Throw(CalibrationErrorReason::kCoplanar,
          std::string(kStage) +
              ": the world points are coplanar; the 11-parameter solution needs points "
              "off one plane");
  }

  // Eq. 2.19 with c34 = 1, on normalised coordinates (Hartley) for conditioning.
  const auto n = static_cast<Eigen::Index>(world_mm.size());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * n, 11);
  Eigen::VectorXd b(2 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto iu = static_cast<size_t>(i);
    const Eigen::Vector3d x = tw.Apply(world_mm[iu]);
    const Eigen::Vector2d u = ti.Apply(image_px[iu]);
    a.block<1, 3>(2 * i, 0) = x.transpose();
    a(2 * i, 3) = 1.0;
    a.block<1, 3>(2 * i, 8) = -u.x() * x.transpose();
    b(2 * i) = u.x();
    a.block<1, 3>(2 * i + 1, 4) = x.transpose();
    a(2 * i + 1, 7) = 1.0;
    a.block<1, 3>(2 * i + 1, 8) = -u.y() * x.transpose();
    b(2 * i + 1) = u.y();
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  qr.setThreshold(1e-10);
  if (qr.rank() < 11) {
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(kStage) + ": the linear system has rank " + std::to_string(qr.rank()) +
              " < 11 (points too few, collinear or in a critical configuration)");
  }
  const Eigen::VectorXd c = qr.solve(b);
  Matrix34d cn;
  cn << c(0), c(1), c(2), c(3), c(4), c(5), c(6), c(7), c(8), c(9), c(10), 1.0;
  DltSolution out;
  out.matrix = ti.Inverse() * cn * tw.Matrix();
  if (!out.matrix.allFinite() || std::abs(out.matrix.leftCols<3>().determinant()) < 1e-300)
    Throw(CalibrationErrorReason::kDegenerate, std::string(kStage) + ": singular camera matrix");
  Decompose(&out);
  std::vector<double> errors;
  for (size_t i = 0; i < world_mm.size(); ++i) {
    const Eigen::Vector3d h = out.matrix * world_mm[i].homogeneous();
    errors.push_back((h.hnormalized() - image_px[i]).norm());
  }
  out.rms_px = RmsOf(errors);
  return out;
}

// Thesis 6.1, Tsai 1987 section on non-coplanar calibration points.
TsaiLinearSolution SolveTsaiLinear(const std::vector<Eigen::Vector3d>& world_mm,
                                   const std::vector<Eigen::Vector2d>& image_px,
                                   const Eigen::Vector2d& principal_point_px) {
  constexpr const char* kStage = "Tsai radial alignment constraint";
  CheckCorrespondences(kStage, world_mm, image_px, 8);
  if (!principal_point_px.allFinite())
    Throw(CalibrationErrorReason::kInvalidInput, std::string(kStage) + ": principal point");
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& w : world_mm) centroid += w;
  centroid /= static_cast<double>(world_mm.size());
  if (internal::OutOfPlaneRms(world_mm) <= 1e-9 * (internal::RmsSpread(world_mm) + 1e-300)) {
    Throw(CalibrationErrorReason::kCoplanar,
          std::string(kStage) +
              ": the world points are coplanar; the non-coplanar RAC needs "
              "points off one plane");
  }
  const RacSolution rac = SolveRac(kStage, world_mm, image_px, principal_point_px, centroid);
  const Eigen::Vector2d ftz =
      SolveFocalAndTz(kStage, world_mm, image_px, principal_point_px, centroid, rac);
  const Eigen::Matrix3d& r = rac.rotation;
  const double sx = rac.sx;
  TsaiLinearSolution out;
  out.rotation = r;
  out.translation = Eigen::Vector3d(rac.tx, rac.ty, ftz(1)) - r * centroid;
  out.f_px = ftz(0);
  out.sx = sx;
  geometry::Intrinsics in;
  in.fx = sx * ftz(0);
  in.fy = ftz(0);
  in.cx = principal_point_px.x();
  in.cy = principal_point_px.y();
  in.k1 = in.k2 = 0.0;
  const geometry::PinholeModel model(in, geometry::Pose{out.rotation, out.translation});
  std::vector<double> errors;
  for (size_t i = 0; i < world_mm.size(); ++i) {
    const auto p = model.Project(world_mm[i]);
    errors.push_back(p ? (*p - image_px[i]).norm() : HUGE_VAL);
  }
  out.rms_px = RmsOf(errors);
  return out;
}

// Thesis 6.1: Tsai two-stage camera calibration.
CameraCalibration CalibrateCamera(const std::vector<TargetView>& views, int width, int height,
                                  const CameraCalibrationParams& params) {
  constexpr const char* kStage = "camera calibration";
  std::string why;
  if (!params.IsValid(&why))
    Throw(CalibrationErrorReason::kInvalidParams, std::string(kStage) + ": " + why);
  if (width <= 0 || height <= 0) {
    Throw(CalibrationErrorReason::kInvalidInput, std::string(kStage) + ": image size " +
                                                     std::to_string(width) + "x" +
                                                     std::to_string(height) + " is not positive");
  }
  const PooledPoints points = PoolViews(kStage, views);
  const std::vector<Eigen::Vector3d>& world = points.world;
  const std::vector<Eigen::Vector2d>& image = points.image;
  CheckPointSpread(kStage, world, views.size(), params);
  const Eigen::Vector2d principal =
      params.principal_point_px.value_or(Eigen::Vector2d((width - 1) / 2.0, (height - 1) / 2.0));

  CameraCalibration out;
  CameraCalibrationReport& report = out.report;
  report.num_points = static_cast<int>(world.size());
  report.num_views = static_cast<int>(views.size());
  report.dlt = SolveDlt(world, image);  // stage 1
  try {
    report.tsai = SolveTsaiLinear(world, image, principal);  // stage 2, linear part
  } catch (const CalibrationError& e) {
    report.tsai_failure = e.what();  // the DLT start below may still give a calibration
  }

  // Starting models: Tsai's (the thesis method) and the DLT's; the
  // refinement keeps whichever ends lower (they normally meet, and then
  // Tsai's is kept).
  const StartingModels starts = StartsOf(report, params, principal);
  std::string failures = report.tsai ? "" : " (" + report.tsai_failure + ")";
  std::optional<internal::PinholeRefinement> best =
      RefineBest(points, starts, params, report, &failures);
  if (!best) {
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(kStage) + ": no linear solution gives a usable camera" + failures);
  }
  out.model = best->model;
  report.iterations = best->iterations;
  report.converged = best->converged;
  report.residual_sigma_px = best->residual_sigma;
  report.f_px = out.model.intrinsics().fy;
  report.sx = out.model.intrinsics().fx / out.model.intrinsics().fy;
  if (best->covariance) report.sigmas = SigmasOf(*best->covariance, report);
  ReportResiduals(points, views.size(), out.model, report);
  return out;
}

}  // namespace bsls::calibration
