#include "bsls/simulator/lesion.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace bsls::simulator {
namespace {

// Vertical rays start this high above the base plane (mm).
constexpr double kAboveEverythingMm = 1.0e5;
// Bisection rounds refining a crossing found by marching (0.25 mm / 2^50).
constexpr int kBisectionRounds = 50;
// A ray whose horizontal direction is shorter than this is vertical.
constexpr double kVerticalRayEpsilon = 1e-12;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

}  // namespace

bool LesionParams::IsValid(std::string* error) const {
  if (!centre_xy_mm.allFinite()) return Fail(error, "lesion centre_xy_mm must be finite");
  if (!(std::isfinite(height_mm) && height_mm != 0.0))
    return Fail(error, "lesion height_mm must be finite and non-zero (> 0 lump, < 0 cavity)");
  if (!(std::isfinite(radius_mm) && radius_mm > 0.0))
    return Fail(error, "lesion radius_mm must be positive and finite");
  if (!(top_radius_mm >= 0.0 && top_radius_mm < radius_mm))
    return Fail(error, "lesion top_radius_mm must lie in [0, radius_mm)");
  return true;
}

double LesionParams::ProfileAt(double r_mm) const {
  if (r_mm <= top_radius_mm) return height_mm;
  if (r_mm >= radius_mm) return 0.0;
  const double w = radius_mm - top_radius_mm;
  return height_mm * 0.5 * (1.0 + std::cos(std::numbers::pi * (r_mm - top_radius_mm) / w));
}

double LesionParams::DisplacementAt(const Eigen::Vector2d& xy_mm) const {
  return ProfileAt((xy_mm - centre_xy_mm).norm());
}

Eigen::Vector2d LesionParams::GradientAt(const Eigen::Vector2d& xy_mm) const {
  const Eigen::Vector2d offset = xy_mm - centre_xy_mm;
  const double r = offset.norm();
  if (r <= top_radius_mm || r >= radius_mm) return Eigen::Vector2d::Zero();
  const double w = radius_mm - top_radius_mm;
  const double dh_dr = -height_mm * 0.5 * std::numbers::pi / w *
                       std::sin(std::numbers::pi * (r - top_radius_mm) / w);
  return dh_dr * offset / r;
}

double LesionParams::RadiusAtLevel(double fraction) const {
  // |h| = fraction |H| on the skirt: (1 + cos(pi s / w)) / 2 = fraction.
  const double w = radius_mm - top_radius_mm;
  return top_radius_mm + w / std::numbers::pi * std::acos(2.0 * fraction - 1.0);
}

double LesionParams::Volume() const {
  const double r0 = top_radius_mm;
  const double w = radius_mm - top_radius_mm;
  const double pi = std::numbers::pi;
  return pi * height_mm * (r0 * r0 + w * w / 2.0 + r0 * w - 2.0 * w * w / (pi * pi));
}

LesionSurface::LesionSurface(std::shared_ptr<const Surface> base, std::vector<LesionParams> lesions)
    : base_(std::move(base)), lesions_(std::move(lesions)) {
  if (!base_) throw std::invalid_argument("lesion surface: base surface is null");
  for (std::size_t i = 0; i < lesions_.size(); ++i) {
    std::string why;
    if (!lesions_[i].IsValid(&why))
      throw std::invalid_argument("lesion " + std::to_string(i) + ": " + why);
    for (std::size_t j = 0; j < i; ++j) {
      const double gap = (lesions_[i].centre_xy_mm - lesions_[j].centre_xy_mm).norm();
      if (gap < lesions_[i].radius_mm + lesions_[j].radius_mm)
        throw std::invalid_argument("lesion " + std::to_string(i) + " overlaps lesion " +
                                    std::to_string(j));
    }
  }
}

std::string LesionSurface::Name() const {
  return base_->Name() + " + " + std::to_string(lesions_.size()) + " lesions";
}

double LesionSurface::DisplacementAt(const Eigen::Vector2d& xy_mm) const {
  double sum = 0.0;
  for (const LesionParams& lesion : lesions_) sum += lesion.DisplacementAt(xy_mm);
  return sum;
}

std::optional<Hit> LesionSurface::BaseBelow(const Eigen::Vector2d& xy_mm) const {
  geometry::Ray down;
  down.origin = Eigen::Vector3d(xy_mm.x(), xy_mm.y(), kAboveEverythingMm);
  down.direction = -Eigen::Vector3d::UnitZ();
  return base_->Intersect(down, std::numeric_limits<double>::infinity());
}

std::optional<double> LesionSurface::BaseHeightAt(const Eigen::Vector2d& xy_mm) const {
  const auto hit = BaseBelow(xy_mm);
  if (!hit) return std::nullopt;
  return hit->point.z();
}

std::optional<double> LesionSurface::HeightAt(const Eigen::Vector2d& xy_mm) const {
  const auto base = BaseHeightAt(xy_mm);
  if (!base) return std::nullopt;
  return *base + DisplacementAt(xy_mm);
}

std::optional<Hit> LesionSurface::Intersect(const geometry::Ray& ray, double max_distance) const {
  std::optional<Hit> best;
  double limit = max_distance;
  if (auto hit = base_->Intersect(ray, max_distance)) {
    if (DisplacementAt(hit->point.head<2>()) == 0.0) {
      bool inside_disc = false;
      for (const LesionParams& lesion : lesions_)
        inside_disc |= (hit->point.head<2>() - lesion.centre_xy_mm).norm() < lesion.radius_mm;
      if (!inside_disc) {
        best = hit;
        limit = hit->distance;
      }
    }
  }
  // Signed height of the ray above the displaced surface at distance t.
  auto gap_at = [&](double t) -> std::optional<double> {
    const Eigen::Vector3d p = ray.At(t);
    const auto z = HeightAt(p.head<2>());
    if (!z) return std::nullopt;
    return p.z() - *z;
  };
  std::optional<double> found;
  for (const LesionParams& lesion : lesions_) {
    const Eigen::Vector2d o = ray.origin.head<2>() - lesion.centre_xy_mm;
    const Eigen::Vector2d d = ray.direction.head<2>();
    const double a = d.squaredNorm();
    if (a < kVerticalRayEpsilon) {
      if (o.norm() >= lesion.radius_mm || ray.direction.z() == 0.0) continue;
      const auto z = HeightAt(ray.origin.head<2>());
      if (!z) continue;
      const double t = (*z - ray.origin.z()) / ray.direction.z();
      if (t > kMinHitDistanceMm && t < limit) {
        limit = t;
        found = t;
      }
      continue;
    }
    const double b = o.dot(d);
    const double c = o.squaredNorm() - lesion.radius_mm * lesion.radius_mm;
    const double disc = b * b - a * c;
    if (disc <= 0.0) continue;
    const double t_in = std::max((-b - std::sqrt(disc)) / a, kMinHitDistanceMm);
    const double t_out = std::min((-b + std::sqrt(disc)) / a, limit);
    if (t_in >= t_out) continue;
    const double dt = kLesionMarchStepMm / std::sqrt(a);
    std::optional<double> previous_gap;
    double previous_t = t_in;
    for (double t = t_in;; t = std::min(t + dt, t_out)) {
      const auto gap = gap_at(t);
      if (gap && previous_gap && ((*gap <= 0.0) != (*previous_gap <= 0.0))) {
        double lo = previous_t, hi = t;
        const bool lo_above = *previous_gap > 0.0;
        for (int round = 0; round < kBisectionRounds; ++round) {
          const double mid = 0.5 * (lo + hi);
          const auto g = gap_at(mid);
          if (!g) break;
          if ((*g > 0.0) == lo_above)
            lo = mid;
          else
            hi = mid;
        }
        const double t_hit = 0.5 * (lo + hi);
        if (t_hit < limit) {
          limit = t_hit;
          found = t_hit;
        }
        break;
      }
      previous_gap = gap;
      previous_t = t;
      if (t >= t_out) break;
    }
  }
  if (!found) return best;
  Hit hit;
  hit.distance = *found;
  hit.point = ray.At(*found);
  const auto base = BaseBelow(hit.point.head<2>());
  Eigen::Vector3d base_normal = base ? base->geometric_normal : Eigen::Vector3d::UnitZ();
  if (base && base->normal.z() < 0.0) base_normal = -base_normal;
  Eigen::Vector2d slope = Eigen::Vector2d::Zero();
  if (std::abs(base_normal.z()) > 1e-9) slope = -base_normal.head<2>() / base_normal.z();
  for (const LesionParams& lesion : lesions_) slope += lesion.GradientAt(hit.point.head<2>());
  Eigen::Vector3d normal(-slope.x(), -slope.y(), 1.0);
  normal.normalize();
  if (base && base->normal.z() < 0.0) normal = -normal;
  hit.normal = normal;
  hit.geometric_normal = normal;
  return hit;
}

LesionTruth LesionSurface::Truth(std::size_t index, double level_fraction, double step_mm) const {
  if (index >= lesions_.size())
    throw std::invalid_argument("lesion truth: index " + std::to_string(index) + " of " +
                                std::to_string(lesions_.size()) + " lesions");
  if (!(level_fraction > 0.0 && level_fraction <= 1.0))
    throw std::invalid_argument("lesion truth: level_fraction must lie in (0, 1]");
  if (!(step_mm > 0.0 && std::isfinite(step_mm)))
    throw std::invalid_argument("lesion truth: step_mm must be positive and finite");
  const LesionParams& lesion = lesions_[index];
  LesionTruth truth;
  truth.peak_mm = lesion.height_mm;
  truth.volume_mm3 = lesion.Volume();
  truth.level_fraction = level_fraction;
  truth.level_radius_mm = lesion.RadiusAtLevel(level_fraction);
  const double radius = truth.level_radius_mm;
  const int n_r = std::max(1, static_cast<int>(std::ceil(radius / step_mm)));
  const int n_theta =
      std::max(16, static_cast<int>(std::ceil(2.0 * std::numbers::pi * radius / step_mm)));
  const double dr = radius / n_r;
  const double dtheta = 2.0 * std::numbers::pi / n_theta;
  for (int i = 0; i < n_r; ++i) {
    const double r = (i + 0.5) * dr;
    for (int j = 0; j < n_theta; ++j) {
      const double theta = (j + 0.5) * dtheta;
      const Eigen::Vector2d xy =
          lesion.centre_xy_mm + r * Eigen::Vector2d(std::cos(theta), std::sin(theta));
      const auto base = BaseBelow(xy);
      if (!base || std::abs(base->geometric_normal.z()) < 1e-9)
        throw std::runtime_error("lesion truth: no base surface under (" + std::to_string(xy.x()) +
                                 ", " + std::to_string(xy.y()) + ")");
      const Eigen::Vector2d base_slope =
          -base->geometric_normal.head<2>() / base->geometric_normal.z();
      const double cell = r * dr * dtheta;
      truth.area_on_base_mm2 += cell * std::sqrt(1.0 + base_slope.squaredNorm());
      truth.area_on_lesion_mm2 +=
          cell * std::sqrt(1.0 + (base_slope + lesion.GradientAt(xy)).squaredNorm());
    }
  }
  return truth;
}

}  // namespace bsls::simulator
