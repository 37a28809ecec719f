#include "bsls/simulator/surface.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace bsls::simulator {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// Rays closer to parallel with a plane than this (|cos|) miss it.
constexpr double kParallelCos = 1e-12;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

bool AllFinite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

PlaneSurface::PlaneSurface(const Eigen::Vector3d& point, const Eigen::Vector3d& normal)
    : point_(point), normal_(normal.normalized()) {
  if (!AllFinite(point) || !(normal.norm() > 0.0) || !AllFinite(normal))
    throw std::invalid_argument("PlaneSurface: point and normal must be finite, normal non-zero");
}

PlaneSurface PlaneSurface::Horizontal(double z_mm) {
  return PlaneSurface(Eigen::Vector3d(0.0, 0.0, z_mm), Eigen::Vector3d::UnitZ());
}

std::optional<Hit> PlaneSurface::Intersect(const geometry::Ray& ray, double max_distance) const {
  const double denom = normal_.dot(ray.direction);
  if (std::abs(denom) < kParallelCos) return std::nullopt;
  const double t = normal_.dot(point_ - ray.origin) / denom;
  if (!(t > kMinHitDistanceMm && t < max_distance)) return std::nullopt;
  Hit hit;
  hit.distance = t;
  hit.point = ray.At(t);
  hit.normal = normal_;
  hit.geometric_normal = normal_;
  return hit;
}

std::string PlaneSurface::Name() const {
  std::ostringstream out;
  out << "plane through (" << point_.x() << ", " << point_.y() << ", " << point_.z()
      << ") mm, normal (" << normal_.x() << ", " << normal_.y() << ", " << normal_.z() << ")";
  return out.str();
}

bool RampParams::IsValid(std::string* error) const {
  if (!foot_xy_mm.allFinite()) return Fail(error, "ramp foot_xy_mm must be finite");
  if (!std::isfinite(rise_azimuth_deg)) return Fail(error, "ramp rise_azimuth_deg must be finite");
  if (!(slope_deg > 0.0 && slope_deg < 90.0))
    return Fail(error, "ramp slope_deg must lie in (0, 90) degrees");
  if (!(run_mm > 0.0 && std::isfinite(run_mm)))
    return Fail(error, "ramp run_mm must be positive and finite");
  if (!(width_mm > 0.0 && std::isfinite(width_mm)))
    return Fail(error, "ramp width_mm must be positive and finite");
  return true;
}

RampSurface::RampSurface(const RampParams& params) : params_(params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument("RampSurface: " + error);
  const double azimuth = params.rise_azimuth_deg * kDegToRad;
  const double slope = params.slope_deg * kDegToRad;
  const Eigen::Vector3d rise(std::cos(azimuth), std::sin(azimuth), 0.0);
  foot_ = Eigen::Vector3d(params.foot_xy_mm.x(), params.foot_xy_mm.y(), 0.0);
  up_slope_ = std::cos(slope) * rise + std::sin(slope) * Eigen::Vector3d::UnitZ();
  across_ = Eigen::Vector3d::UnitZ().cross(rise);
  normal_ = up_slope_.cross(across_).normalized();
  if (normal_.z() < 0.0) normal_ = -normal_;
  slope_length_ = params.run_mm / std::cos(slope);
}

std::optional<Hit> RampSurface::Intersect(const geometry::Ray& ray, double max_distance) const {
  const double denom = normal_.dot(ray.direction);
  if (std::abs(denom) < kParallelCos) return std::nullopt;
  const double t = normal_.dot(foot_ - ray.origin) / denom;
  if (!(t > kMinHitDistanceMm && t < max_distance)) return std::nullopt;
  const Eigen::Vector3d point = ray.At(t);
  const Eigen::Vector3d local = point - foot_;
  const double along = local.dot(up_slope_);
  const double across = local.dot(across_);
  if (along < 0.0 || along > slope_length_ || std::abs(across) > params_.width_mm / 2.0)
    return std::nullopt;
  Hit hit;
  hit.distance = t;
  hit.point = point;
  hit.normal = normal_;
  hit.geometric_normal = normal_;
  return hit;
}

std::string RampSurface::Name() const {
  std::ostringstream out;
  out << "ramp " << params_.slope_deg << " deg rising towards azimuth " << params_.rise_azimuth_deg
      << " deg from foot (" << params_.foot_xy_mm.x() << ", " << params_.foot_xy_mm.y() << ") mm";
  return out.str();
}

double RampSurface::PlaneHeightAt(double x_mm, double y_mm) const {
  // Plane: normal . (X - foot) = 0, solved for z.
  return foot_.z() -
         (normal_.x() * (x_mm - foot_.x()) + normal_.y() * (y_mm - foot_.y())) / normal_.z();
}

bool BallParams::IsValid(std::string* error) const {
  if (!centre_mm.allFinite()) return Fail(error, "ball centre_mm must be finite");
  if (!(radius_mm > 0.0 && std::isfinite(radius_mm)))
    return Fail(error, "ball radius_mm must be positive and finite");
  if (std::isnan(cut_below_z_mm)) return Fail(error, "ball cut_below_z_mm must not be NaN");
  return true;
}

BallSurface::BallSurface(const BallParams& params) : params_(params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument("BallSurface: " + error);
}

std::optional<Hit> BallSurface::Intersect(const geometry::Ray& ray, double max_distance) const {
  const Eigen::Vector3d oc = ray.origin - params_.centre_mm;
  const double b = oc.dot(ray.direction);
  const double c = oc.squaredNorm() - params_.radius_mm * params_.radius_mm;
  const double disc = b * b - c;
  if (disc < 0.0) return std::nullopt;
  const double root = std::sqrt(disc);
  // Numerically stable pair of roots.
  const double q = b > 0.0 ? -(b + root) : -(b - root);
  double t0 = q;
  double t1 = q != 0.0 ? c / q : -q;
  if (t0 > t1) std::swap(t0, t1);
  for (const double t : {t0, t1}) {
    if (!(t > kMinHitDistanceMm && t < max_distance)) continue;
    const Eigen::Vector3d point = ray.At(t);
    if (point.z() < params_.cut_below_z_mm) continue;
    Hit hit;
    hit.distance = t;
    hit.point = point;
    hit.normal = (point - params_.centre_mm).normalized();
    hit.geometric_normal = hit.normal;
    return hit;
  }
  return std::nullopt;
}

std::string BallSurface::Name() const {
  std::ostringstream out;
  out << "ball radius " << params_.radius_mm << " mm at (" << params_.centre_mm.x() << ", "
      << params_.centre_mm.y() << ", " << params_.centre_mm.z()
      << ") mm, cut below z = " << params_.cut_below_z_mm << " mm";
  return out.str();
}

bool CylinderParams::IsValid(std::string* error) const {
  if (!centre_mm.allFinite()) return Fail(error, "cylinder centre_mm must be finite");
  if (!axis.allFinite() || !(axis.norm() > 0.0))
    return Fail(error, "cylinder axis must be finite and non-zero");
  if (!(radius_mm > 0.0 && std::isfinite(radius_mm)))
    return Fail(error, "cylinder radius_mm must be positive and finite");
  if (!(length_mm > 0.0 && std::isfinite(length_mm)))
    return Fail(error, "cylinder length_mm must be positive and finite");
  if (std::isnan(cut_below_z_mm)) return Fail(error, "cylinder cut_below_z_mm must not be NaN");
  return true;
}

CylinderSurface::CylinderSurface(const CylinderParams& params) : params_(params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument("CylinderSurface: " + error);
  axis_ = params_.axis.normalized();
}

std::optional<Hit> CylinderSurface::Intersect(const geometry::Ray& ray, double max_distance) const {
  const Eigen::Vector3d w = ray.origin - params_.centre_mm;
  const double w_axial = w.dot(axis_);
  const double d_axial = ray.direction.dot(axis_);
  const Eigen::Vector3d w_perp = w - w_axial * axis_;
  const Eigen::Vector3d d_perp = ray.direction - d_axial * axis_;
  const double half = params_.length_mm / 2.0;
  const double r2 = params_.radius_mm * params_.radius_mm;
  std::optional<Hit> best;
  auto consider = [&](double t, const Eigen::Vector3d& normal) {
    if (!(t > kMinHitDistanceMm && t < max_distance)) return;
    const Eigen::Vector3d point = ray.At(t);
    if (point.z() < params_.cut_below_z_mm) return;
    Hit hit;
    hit.distance = t;
    hit.point = point;
    hit.normal = normal;
    hit.geometric_normal = normal;
    best = hit;
    max_distance = t;
  };
  // Mantle: |w_perp + t d_perp| = r with the axial coordinate within the caps.
  const double a = d_perp.squaredNorm();
  if (a > kParallelCos) {
    const double b = w_perp.dot(d_perp);
    const double c = w_perp.squaredNorm() - r2;
    const double disc = b * b - a * c;
    if (disc >= 0.0) {
      const double root = std::sqrt(disc);
      for (const double t : {(-b - root) / a, (-b + root) / a}) {
        if (std::abs(w_axial + t * d_axial) > half) continue;
        const Eigen::Vector3d radial = w_perp + t * d_perp;
        consider(t, radial / params_.radius_mm);
      }
    }
  }
  // Caps: the discs at axial coordinates -+half.
  if (params_.caps && std::abs(d_axial) > kParallelCos) {
    for (const double end : {-half, half}) {
      const double t = (end - w_axial) / d_axial;
      if ((w_perp + t * d_perp).squaredNorm() > r2) continue;
      consider(t, end > 0.0 ? axis_ : Eigen::Vector3d(-axis_));
    }
  }
  return best;
}

std::string CylinderSurface::Name() const {
  std::ostringstream out;
  out << "cylinder radius " << params_.radius_mm << " mm, length " << params_.length_mm
      << " mm at (" << params_.centre_mm.x() << ", " << params_.centre_mm.y() << ", "
      << params_.centre_mm.z() << ") mm along (" << axis_.x() << ", " << axis_.y() << ", "
      << axis_.z() << "), cut below z = " << params_.cut_below_z_mm << " mm";
  return out.str();
}

}  // namespace bsls::simulator
