#include "bsls/simulator/albedo.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace bsls::simulator {
namespace {

// Plane waves summed for the smooth variation.
constexpr int kWaveCount = 4;
// Their wavelengths spread over [kMin, kMax] x wavelength_mm.
constexpr double kWavelengthMin = 0.7;
constexpr double kWavelengthMax = 1.4;

double SmoothStep(double edge0, double edge1, double x) {
  if (edge0 == edge1) return x < edge0 ? 0.0 : 1.0;
  const double t = std::clamp((x - edge0) / (edge1 - edge0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace

bool AlbedoParams::IsValid(std::string* error) const {
  auto fail = [error](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!(base > 0.0 && base <= 1.0)) return fail("albedo base must lie in (0, 1]");
  if (!(variation >= 0.0 && variation < 1.0)) return fail("albedo variation must lie in [0, 1)");
  if (!(wavelength_mm > 0.0 && std::isfinite(wavelength_mm)))
    return fail("albedo wavelength_mm must be positive and finite");
  for (size_t i = 0; i < patches.size(); ++i) {
    const AlbedoPatch& p = patches[i];
    const std::string name = "albedo patch " + std::to_string(i) + ": ";
    if (!p.centre_xy_mm.allFinite()) return fail(name + "centre_xy_mm must be finite");
    if (!(p.semi_axis_x_mm > 0.0 && p.semi_axis_y_mm > 0.0 && std::isfinite(p.semi_axis_x_mm) &&
          std::isfinite(p.semi_axis_y_mm)))
      return fail(name + "semi-axes must be positive and finite");
    if (!std::isfinite(p.rotation_deg)) return fail(name + "rotation_deg must be finite");
    if (!(p.albedo >= 0.0 && p.albedo <= 1.0)) return fail(name + "albedo must lie in [0, 1]");
    if (!(p.edge_mm >= 0.0 && std::isfinite(p.edge_mm)))
      return fail(name + "edge_mm must be non-negative and finite");
  }
  return true;
}

AlbedoField::AlbedoField() : AlbedoField(AlbedoParams{}) {}

AlbedoField::AlbedoField(const AlbedoParams& params) : params_(params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument("AlbedoField: " + error);
  std::mt19937 rng(params.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double weight_sum = 0.0;
  for (int i = 0; i < kWaveCount; ++i) {
    // Uniform direction on the sphere.
    const double z = 2.0 * unit(rng) - 1.0;
    const double azimuth = 2.0 * std::numbers::pi * unit(rng);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d direction(r * std::cos(azimuth), r * std::sin(azimuth), z);
    const double wavelength =
        params.wavelength_mm * (kWavelengthMin + (kWavelengthMax - kWavelengthMin) * unit(rng));
    Wave wave;
    wave.k = direction * (2.0 * std::numbers::pi / wavelength);
    wave.phase = 2.0 * std::numbers::pi * unit(rng);
    wave.weight = 0.5 + unit(rng);
    weight_sum += wave.weight;
    waves_.push_back(wave);
  }
  for (auto& wave : waves_) wave.weight /= weight_sum;
  for (const AlbedoPatch& patch : params.patches) {
    const double angle = patch.rotation_deg * std::numbers::pi / 180.0;
    patches_.push_back({patch, std::cos(angle), std::sin(angle)});
  }
}

double AlbedoField::At(const Eigen::Vector3d& world) const {
  double wave_sum = 0.0;
  for (const Wave& wave : waves_)
    wave_sum += wave.weight * std::cos(wave.k.dot(world) + wave.phase);
  double albedo = params_.base * (1.0 + params_.variation * wave_sum);
  for (const PreparedPatch& prepared : patches_) {
    const AlbedoPatch& p = prepared.patch;
    const double dx = world.x() - p.centre_xy_mm.x();
    const double dy = world.y() - p.centre_xy_mm.y();
    // Coordinates in the patch's own axes (mm).
    const double ax = prepared.cos_r * dx + prepared.sin_r * dy;
    const double ay = -prepared.sin_r * dx + prepared.cos_r * dy;
    double signed_distance = 0.0;
    if (p.shape == PatchShape::kRectangle) {
      // Exact signed distance to the rectangle's outline; nothing to paint
      // beyond half the soft edge (most patches of a target, most of the time).
      const double qx = std::abs(ax) - p.semi_axis_x_mm;
      const double qy = std::abs(ay) - p.semi_axis_y_mm;
      if (qx >= p.edge_mm / 2.0 || qy >= p.edge_mm / 2.0) continue;
      signed_distance =
          std::hypot(std::max(qx, 0.0), std::max(qy, 0.0)) + std::min(std::max(qx, qy), 0.0);
    } else {
      // Normalised by the semi-axes; signed distance to first order: (r - 1) / |grad r|.
      const double ex = ax / p.semi_axis_x_mm;
      const double ey = ay / p.semi_axis_y_mm;
      const double r = std::hypot(ex, ey);
      signed_distance = -std::min(p.semi_axis_x_mm, p.semi_axis_y_mm);
      if (r > 1e-12) {
        const double gx = ex / p.semi_axis_x_mm;
        const double gy = ey / p.semi_axis_y_mm;
        const double gradient = std::hypot(gx, gy) / r;
        signed_distance = (r - 1.0) / gradient;
      }
    }
    const double inside = 1.0 - SmoothStep(-p.edge_mm / 2.0, p.edge_mm / 2.0, signed_distance);
    albedo += inside * (p.albedo - albedo);
  }
  return std::clamp(albedo, 0.0, 1.0);
}

}  // namespace bsls::simulator
