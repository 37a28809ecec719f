#include "bsls/calibration/projector_calibration.h"

#include <Eigen/Geometry>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <set>
#include <sstream>
#include <string>

#include "pinhole_refinement.h"
#include "point_set_geometry.h"

namespace bsls::calibration {
namespace {

[[noreturn]] void Throw(CalibrationErrorReason reason, const std::string& message) {
  throw CalibrationError(reason, message);
}

double Rms(const std::vector<double>& values, const std::vector<bool>& use) {
  double sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    if (!use[i]) continue;
    sum += values[i] * values[i];
    ++count;
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

double MaxAbs(const std::vector<double>& values, const std::vector<bool>& use) {
  double m = 0.0;
  for (size_t i = 0; i < values.size(); ++i)
    if (use[i]) m = std::max(m, std::abs(values[i]));
  return m;
}

int CountTrue(const std::vector<bool>& flags) {
  return static_cast<int>(std::count(flags.begin(), flags.end(), true));
}

// Checks the stripe points common to (a) and (b).
void CheckStripes(const char* stage, const std::vector<StripePoint>& points,
                  const StripeFitParams& params, size_t min_points, size_t min_lines) {
  std::string why;
  if (!params.IsValid(&why))
    Throw(CalibrationErrorReason::kInvalidParams, std::string(stage) + ": " + why);
  std::set<int> lines;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].world_mm.allFinite()) {
      std::ostringstream os;
      os << stage << ": point " << i << " has a non-finite coordinate";
      Throw(CalibrationErrorReason::kInvalidInput, os.str());
    }
    lines.insert(points[i].line);
  }
  if (points.size() < min_points || lines.size() < min_lines) {
    std::ostringstream os;
    os << stage << ": " << points.size() << " points on " << lines.size() << " lines; at least "
       << min_points << " points on " << min_lines << " lines are needed";
    Throw(CalibrationErrorReason::kTooFewPoints, os.str());
  }
  std::vector<Eigen::Vector3d> world;
  for (const auto& p : points) world.push_back(p.world_mm);
  if (internal::OutOfPlaneRms(world) <= 1e-9 * (internal::RmsSpread(world) + 1e-300)) {
    Throw(CalibrationErrorReason::kCoplanar,
          std::string(stage) +
              ": all points lie in one plane (one screen); the tilt of the light planes needs "
              "screens at two or more z");
  }
}

// The thesis's two-pass scheme (6.2.1): fit on the kept points, measure every
// point's distance to the fit, keep those within k sigma, fit again. `fit`
// fits the flagged points and returns every point's residual.
StripeFitReport FitWithRejection(
    size_t count, double outlier_sigma, int rounds, double min_distance, size_t min_points,
    const char* stage, const std::function<std::vector<double>(const std::vector<bool>&)>& fit) {
  StripeFitReport report;
  report.inlier.assign(count, true);
  std::vector<double> residuals = fit(report.inlier);
  report.first_pass_rms_mm = Rms(residuals, report.inlier);
  for (int round = 0; round < rounds && outlier_sigma > 0.0; ++round) {
    const double threshold = std::max(outlier_sigma * Rms(residuals, report.inlier), min_distance);
    std::vector<bool> keep(count);
    for (size_t i = 0; i < count; ++i) keep[i] = std::abs(residuals[i]) <= threshold;
    if (keep == report.inlier) break;
    if (static_cast<size_t>(CountTrue(keep)) < min_points) {
      std::ostringstream os;
      os << stage << ": outlier rejection at " << outlier_sigma << " sigma leaves "
         << CountTrue(keep) << " of " << count << " points; at least " << min_points
         << " are needed";
      Throw(CalibrationErrorReason::kTooFewPoints, os.str());
    }
    report.inlier = keep;
    residuals = fit(report.inlier);
  }
  report.points_used = CountTrue(report.inlier);
  report.points_dropped = static_cast<int>(count) - report.points_used;
  report.rms_mm = Rms(residuals, report.inlier);
  report.max_mm = MaxAbs(residuals, report.inlier);
  return report;
}

// Least squares e = m.r + e0 over the flagged points (thesis eq. 6.1-6.2 with
// m = n / d0). nullopt when the flagged points do not determine m.
std::optional<Eigen::Vector4d> SolveParallel(const std::vector<StripePoint>& points,
                                             const std::vector<bool>& use) {
  const int n = CountTrue(use);
  Eigen::MatrixXd a(n, 4);
  Eigen::VectorXd b(n);
  // Centre the coordinates for conditioning; e0 is shifted back below.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < points.size(); ++i)
    if (use[i]) centre += points[i].world_mm;
  centre /= std::max(n, 1);
  int row = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!use[i]) continue;
    a.block<1, 3>(row, 0) = (points[i].world_mm - centre).transpose();
    a(row, 3) = 1.0;
    b(row) = points[i].line;
    ++row;
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  qr.setThreshold(1e-10);
  if (qr.rank() < 4) return std::nullopt;
  Eigen::Vector4d x = qr.solve(b);
  x(3) -= x.head<3>().dot(centre);
  if (!x.allFinite() || !(x.head<3>().norm() > 0.0)) return std::nullopt;
  return x;
}

ParallelPlaneModel ParallelModelOf(const Eigen::Vector4d& x) {
  ParallelPlaneModel model;
  const double m = x.head<3>().norm();
  model.normal = x.head<3>() / m;
  model.spacing_mm = 1.0 / m;
  model.e0 = x(3);
  return model;
}

int LargestComponent(const Eigen::Vector3d& v) {
  int index = 0;
  v.cwiseAbs().maxCoeff(&index);
  return index;
}

// True when the settings FitWithRejection takes are usable (the same for
// every model); otherwise says why, naming the floor distance's field.
bool RejectionIsValid(double outlier_sigma, int rounds, double min_distance,
                      const std::string& distance_field, std::string* error) {
  auto fail = [error](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!std::isfinite(outlier_sigma)) return fail("outlier_sigma must be finite");
  if (outlier_sigma > 0.0 && outlier_sigma < 1.0)
    return fail("outlier_sigma must be >= 1 (or <= 0 to disable rejection)");
  if (rounds < 0) return fail("rejection_rounds must be >= 0");
  if (!(min_distance >= 0.0) || !std::isfinite(min_distance))
    return fail(distance_field + " must be finite and >= 0");
  return true;
}

}  // namespace

std::optional<Eigen::Vector3d> LightPlane::Intersect(const geometry::Ray& ray) const {
  const double along = normal.dot(ray.direction);
  if (std::abs(along) < 1e-12) return std::nullopt;
  const double distance = -SignedDistance(ray.origin) / along;
  if (distance < 0.0) return std::nullopt;
  return ray.At(distance);
}

bool StripeFitParams::IsValid(std::string* error) const {
  return RejectionIsValid(outlier_sigma, rejection_rounds, min_outlier_distance_mm,
                          "min_outlier_distance_mm", error);
}

LightPlane ParallelPlaneModel::PlaneOfLine(double e) const {
  return LightPlane{normal, spacing_mm * (e - e0)};
}

// Thesis 6.2.1: parallel plane projector model.
ParallelPlaneFit FitParallelPlaneModel(const std::vector<StripePoint>& points,
                                       const StripeFitParams& params) {
  constexpr const char* kStage = "parallel-plane projector model";
  constexpr size_t kMinPoints = 4;
  CheckStripes(kStage, points, params, kMinPoints, 2);
  ParallelPlaneFit out;
  auto fit = [&](const std::vector<bool>& use) {
    const auto x = SolveParallel(points, use);
    if (!x) {
      Throw(CalibrationErrorReason::kDegenerate,
            std::string(kStage) +
                ": the points do not determine the planes (too few lines, or "
                "the lines' points are collinear)");
    }
    out.model = ParallelModelOf(*x);
    std::vector<double> distances(points.size());
    for (size_t i = 0; i < points.size(); ++i)
      distances[i] = out.model.PlaneOfLine(points[i].line).SignedDistance(points[i].world_mm);
    return distances;
  };
  out.report = FitWithRejection(points.size(), params.outlier_sigma, params.rejection_rounds,
                                params.min_outlier_distance_mm, kMinPoints, kStage, fit);
  return out;
}

LightPlane PerspectivePlaneModel::PlaneOfLine(double e) const {
  Eigen::Vector3d n = n0 + e * p;
  if (n(gauge_axis) < 0.0) n = -n;
  n.normalize();
  return LightPlane{n, n.dot(centre_mm)};
}

double PerspectivePlaneModel::CentralLine() const {
  const double p2 = p.squaredNorm();
  return p2 > 0.0 ? -p.dot(n0) / p2 : 0.0;
}

// Thesis 6.2.2: full perspective projector model.
PerspectivePlaneFit FitPerspectivePlaneModel(const std::vector<StripePoint>& points,
                                             const StripeFitParams& params) {
  constexpr const char* kStage = "perspective projector model";
  constexpr size_t kMinPoints = 8;
  // A centre further from the points than this many times their spread means parallel planes.
  constexpr double kMaxCentreDistance = 1e4;
  CheckStripes(kStage, points, params, kMinPoints, 3);
  // Gauge: fix to 1 the largest component of the planes' normal, found by the
  // parallel-plane solution on all points (thesis: n_y = 1).
  const auto rough = SolveParallel(points, std::vector<bool>(points.size(), true));
  if (!rough) {
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(kStage) + ": the points do not determine the planes' normal");
  }
  const int g = LargestComponent(rough->head<3>());
  const int a = (g + 1) % 3;
  const int b = (g + 2) % 3;

  PerspectivePlaneFit out;
  PerspectivePlaneModel& model = out.model;
  model.gauge_axis = g;
  double c0 = 0.0;  // -P0.n0
  double c1 = 0.0;  // -P0.p
  bool have_fit = false;
  auto fit = [&](const std::vector<bool>& use) {
    // Eq. 6.6: A X = B, X = (n0_a, n0_b, p_x, p_y, p_z, c0, c1), B = -r_g.
    const int n = CountTrue(use);
    Eigen::MatrixXd m(n, 7);
    Eigen::VectorXd rhs(n);
    int row = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      if (!use[i]) continue;
      const Eigen::Vector3d& r = points[i].world_mm;
      const double e = points[i].line;
      // After the first pass weight by 1 / |n_e|: residuals become distances.
      const double w = have_fit ? 1.0 / (model.n0 + e * model.p).norm() : 1.0;
      m.row(row) << r(a), r(b), e * r.x(), e * r.y(), e * r.z(), 1.0, e;
      m.row(row) *= w;
      rhs(row) = -r(g) * w;
      ++row;
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(m);
    qr.setThreshold(1e-10);
    if (qr.rank() < 7) {
      Throw(CalibrationErrorReason::kDegenerate,
            std::string(kStage) + ": the linear system has rank " + std::to_string(qr.rank()) +
                " < 7 (too few lines or depths)");
    }
    const Eigen::VectorXd x = qr.solve(rhs);
    model.n0(g) = 1.0;
    model.n0(a) = x(0);
    model.n0(b) = x(1);
    model.p = x.segment<3>(2);
    c0 = x(5);
    c1 = x(6);
    have_fit = true;
    std::vector<double> distances(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d& r = points[i].world_mm;
      const double e = points[i].line;
      const Eigen::Vector3d ne = model.n0 + e * model.p;
      distances[i] = (r.dot(ne) + c0 + e * c1) / ne.norm();
    }
    return distances;
  };
  out.report = FitWithRejection(points.size(), params.outlier_sigma, params.rejection_rounds,
                                params.min_outlier_distance_mm, kMinPoints, kStage, fit);

  // The pencil's axis: r.n0 = -c0 and r.p = -c1. Remove the spare degree of
  // freedom by zeroing the axis's largest component (thesis: x0 = 0).
  const Eigen::Vector3d axis = model.n0.cross(model.p);
  if (!(axis.norm() > 1e-9 * model.n0.norm() * model.p.norm()) || !(model.p.norm() > 0.0)) {
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(kStage) +
              ": the light planes are parallel, so there is no finite projector centre; use "
              "the parallel-plane model");
  }
  const int h = LargestComponent(axis);
  const int i = (h + 1) % 3;
  const int j = (h + 2) % 3;
  Eigen::Matrix2d m;
  m << model.n0(i), model.n0(j), model.p(i), model.p(j);
  const Eigen::Vector2d ij = m.inverse() * Eigen::Vector2d(-c0, -c1);
  model.centre_axis = h;
  model.centre_mm(h) = 0.0;
  model.centre_mm(i) = ij(0);
  model.centre_mm(j) = ij(1);
  model.axis_direction = axis.normalized();
  // Nearly parallel planes put the centre absurdly far away: as good as parallel.
  std::vector<Eigen::Vector3d> world;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& point : points) {
    world.push_back(point.world_mm);
    centroid += point.world_mm;
  }
  centroid /= static_cast<double>(points.size());
  if (!model.centre_mm.allFinite() ||
      (model.centre_mm - centroid).norm() > kMaxCentreDistance * internal::RmsSpread(world)) {
    Throw(CalibrationErrorReason::kDegenerate,
          std::string(kStage) +
              ": the light planes are parallel, so there is no finite projector centre; use "
              "the parallel-plane model");
  }
  out.centre_to_origin_mm = model.centre_mm.norm();
  out.axis_to_origin_mm =
      (model.centre_mm - model.centre_mm.dot(model.axis_direction) * model.axis_direction).norm();
  return out;
}

Eigen::Vector2d SlideOfJunction(pattern::Side side, int p, int q) {
  return {pattern::SFromU(side, p), static_cast<double>(q)};
}

bool ProjectorMatrixParams::IsValid(std::string* error) const {
  if (!RejectionIsValid(outlier_sigma, rejection_rounds, min_outlier_distance_d,
                        "min_outlier_distance_d", error))
    return false;
  if (max_iterations < 1) {
    if (error) *error = "max_iterations must be >= 1";
    return false;
  }
  return true;
}

// Thesis 2.3 eq. 2.16: the projector matrix, refined to a pinhole model.
ProjectorMatrixFit FitProjectorMatrix(const std::vector<JunctionPoint>& junctions,
                                      const ProjectorMatrixParams& params) {
  constexpr const char* kStage = "projector matrix";
  std::string why;
  if (!params.IsValid(&why))
    Throw(CalibrationErrorReason::kInvalidParams, std::string(kStage) + ": " + why);
  if (junctions.size() < static_cast<size_t>(kMinCalibrationPoints)) {
    std::ostringstream os;
    os << kStage << ": " << junctions.size() << " junctions; at least " << kMinCalibrationPoints
       << " are needed";
    Throw(CalibrationErrorReason::kTooFewPoints, os.str());
  }
  std::vector<Eigen::Vector3d> world;
  std::vector<Eigen::Vector2d> slide;
  for (size_t i = 0; i < junctions.size(); ++i) {
    if (!junctions[i].world_mm.allFinite() || !junctions[i].slide_st.allFinite()) {
      std::ostringstream os;
      os << kStage << ": junction " << i << " has a non-finite coordinate";
      Throw(CalibrationErrorReason::kInvalidInput, os.str());
    }
    world.push_back(junctions[i].world_mm);
    slide.push_back(junctions[i].slide_st);
  }

  std::array<bool, internal::kPinholeParamCount> free{};
  free.fill(true);
  free[internal::kCx] = free[internal::kCy] = params.refine_principal_point;
  free[internal::kK1] = params.refine_k1;
  free[internal::kK2] = params.refine_k2;
  internal::LmOptions options;
  options.max_iterations = params.max_iterations;

  ProjectorMatrixFit out;
  std::optional<internal::PinholeRefinement> refined;
  auto fit = [&](const std::vector<bool>& use) {
    std::vector<Eigen::Vector3d> w;
    std::vector<Eigen::Vector2d> s;
    for (size_t i = 0; i < world.size(); ++i) {
      if (!use[i]) continue;
      w.push_back(world[i]);
      s.push_back(slide[i]);
    }
    try {
      out.report.dlt = SolveDlt(w, s);
    } catch (const CalibrationError& e) {
      Throw(e.reason(), std::string(kStage) + ": " + e.what());
    }
    const Eigen::Matrix3d& k = out.report.dlt.k;
    geometry::Intrinsics in;
    in.fx = k(0, 0);
    in.fy = k(1, 1);
    in.cx = k(0, 2);
    in.cy = k(1, 2);
    in.k1 = in.k2 = 0.0;
    const geometry::PinholeModel start(
        in, geometry::Pose{out.report.dlt.rotation, out.report.dlt.translation});
    refined = internal::RefinePinhole(w, s, start, internal::FocalForm::kFxFy, free, options);
    if (!refined) {
      Throw(CalibrationErrorReason::kDegenerate,
            std::string(kStage) + ": the linear solution puts junctions behind the projector");
    }
    std::vector<double> errors(world.size());
    for (size_t i = 0; i < world.size(); ++i) {
      const auto projected = refined->model.Project(world[i]);
      errors[i] = projected ? (*projected - slide[i]).norm() : HUGE_VAL;
    }
    return errors;
  };
  const StripeFitReport pass = FitWithRejection(
      junctions.size(), params.outlier_sigma, params.rejection_rounds,
      params.min_outlier_distance_d, static_cast<size_t>(kMinCalibrationPoints), kStage, fit);
  out.model = refined->model;
  out.report.points_used = pass.points_used;
  out.report.points_dropped = pass.points_dropped;
  out.report.rms_d = pass.rms_mm;  // the residuals here are slide distances (d)
  out.report.max_d = pass.max_mm;
  out.report.residual_sigma_d = refined->residual_sigma;
  out.report.inlier = pass.inlier;
  out.report.iterations = refined->iterations;
  out.report.converged = refined->converged;
  const geometry::Intrinsics& in = out.model.intrinsics();
  Eigen::Matrix3d k;
  k << in.fx, 0.0, in.cx, 0.0, in.fy, in.cy, 0.0, 0.0, 1.0;
  out.matrix.leftCols<3>() = k * out.model.pose().rotation;
  out.matrix.col(3) = k * out.model.pose().translation;
  return out;
}

LightPlane LightPlaneOfSlideColumn(const geometry::PinholeModel& projector, double s,
                                   double t_half_extent) {
  if (!(t_half_extent > 0.0) || !std::isfinite(s) || !std::isfinite(t_half_extent)) {
    Throw(CalibrationErrorReason::kInvalidInput,
          "light plane of a slide column: s must be finite and t_half_extent positive");
  }
  const geometry::Ray top = projector.BackProject({s, -t_half_extent});
  const geometry::Ray bottom = projector.BackProject({s, t_half_extent});
  Eigen::Vector3d normal = top.direction.cross(bottom.direction);
  if (!(normal.norm() > 1e-12)) {
    Throw(CalibrationErrorReason::kDegenerate,
          "light plane of a slide column: the column's rays coincide");
  }
  normal.normalize();
  // Towards increasing s: along the device x axis in the world.
  if (normal.dot(projector.pose().rotation.row(0).transpose()) < 0.0) normal = -normal;
  return LightPlane{normal, normal.dot(projector.Centre())};
}

}  // namespace bsls::calibration
