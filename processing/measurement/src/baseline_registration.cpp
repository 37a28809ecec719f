#include "bsls/measurement/baseline_registration.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <utility>
#include <vector>

#include "polygon.h"

namespace bsls::measurement {
namespace {

// Smallest / largest eigenvalue of the scaled normal matrix below this: the
// overlap does not fix every degree of freedom.
constexpr double kDegenerateRatio = 1e-7;
// Robust sigmas (MAD) beyond which a pair is an outlier.
constexpr double kInlierSigmas = 4.0;
constexpr double kMadToSigma = 1.4826;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

bool Positive(double value) { return value > 0.0 && std::isfinite(value); }

// One vertex of the surface paired with the plane of the baseline face
// straight above or below it.
struct Pair {
  Eigen::Vector3d point;   // the surface vertex, moved by the current transform
  Eigen::Vector3d normal;  // unit normal of the baseline face, towards +z
  double distance;         // signed distance of point from that face's plane
};

std::vector<Pair> PairUp(const std::vector<Eigen::Vector3d>& points, const SurfaceQuery& baseline,
                         const Eigen::Isometry3d& transform, double max_pair_mm) {
  std::vector<Pair> pairs;
  pairs.reserve(points.size());
  for (const Eigen::Vector3d& x : points) {
    const Eigen::Vector3d p = transform * x;
    const auto hit = baseline.Above(p.head<2>());
    if (!hit) continue;
    const Eigen::Vector3d n = baseline.FaceNormal(hit->face);
    const double distance = n.dot(p - hit->position);
    if (std::abs(distance) <= max_pair_mm) pairs.push_back({p, n, distance});
  }
  return pairs;
}

// Pairs further than this from the plane are changes of the face (another
// lesion, a moved lip), not noise: left out of a step and of the RMS.
double InlierLimit(const std::vector<Pair>& pairs, double huber_mm) {
  std::vector<double> magnitudes;
  magnitudes.reserve(pairs.size());
  for (const Pair& pair : pairs) magnitudes.push_back(std::abs(pair.distance));
  if (magnitudes.empty()) return huber_mm;
  auto middle = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
  std::nth_element(magnitudes.begin(), middle, magnitudes.end());
  return std::max(kInlierSigmas * kMadToSigma * *middle, 2.0 * huber_mm);
}

// RMS plane distance of the inlier pairs, and their count.
std::pair<double, int> InlierRms(const std::vector<Pair>& pairs, double huber_mm) {
  const double limit = InlierLimit(pairs, huber_mm);
  double sum = 0.0;
  int count = 0;
  for (const Pair& pair : pairs)
    if (std::abs(pair.distance) <= limit) {
      sum += pair.distance * pair.distance;
      ++count;
    }
  return {count > 0 ? std::sqrt(sum / count) : 0.0, count};
}

}  // namespace

bool BaselineParams::IsValid(std::string* error) const {
  if (!Positive(max_pair_mm)) return Fail(error, "baseline max_pair_mm must be positive");
  if (!Positive(huber_mm)) return Fail(error, "baseline huber_mm must be positive");
  if (max_iterations < 1) return Fail(error, "baseline max_iterations must be at least 1");
  if (!Positive(converged_rotation_deg) || !Positive(converged_translation_mm))
    return Fail(error, "baseline convergence thresholds must be positive");
  if (max_points < 100) return Fail(error, "baseline max_points must be at least 100");
  if (min_pairs < 6) return Fail(error, "baseline min_pairs must be at least 6");
  if (!(min_coverage > 0.0 && min_coverage <= 1.0))
    return Fail(error, "baseline min_coverage must lie in (0, 1]");
  return true;
}

BaselineRegistration RegisterToBaseline(const SurfaceQuery& surface, const SurfaceQuery& baseline,
                                        const Polygon2d& exclude, const BaselineParams& params) {
  std::string why;
  if (!params.IsValid(&why)) throw MeasurementError(why);
  if (!exclude.empty()) internal::CheckPolygon(exclude, "baseline exclusion region");

  // The surface's vertices outside the region, evenly thinned.
  const geometry::SurfaceMesh& mesh = surface.mesh();
  std::vector<Eigen::Vector3d> outside;
  for (const Eigen::Vector3d& p : mesh.positions)
    if (exclude.empty() || !internal::Contains(exclude, p.head<2>())) outside.push_back(p);
  if (static_cast<int>(outside.size()) > params.max_points) {
    std::vector<Eigen::Vector3d> thinned;
    const double step = static_cast<double>(outside.size()) / params.max_points;
    for (int i = 0; i < params.max_points; ++i)
      thinned.push_back(outside[static_cast<std::size_t>(i * step)]);
    outside.swap(thinned);
  }

  BaselineRegistration result;
  result.rigid = params.register_rigidly;
  auto check_pairs = [&](const std::vector<Pair>& pairs) {
    if (static_cast<int>(pairs.size()) < params.min_pairs)
      throw MeasurementError("baseline: only " + std::to_string(pairs.size()) +
                             " surface vertices outside the " + "region lie within " +
                             std::to_string(params.max_pair_mm) + " mm of the baseline (at least " +
                             std::to_string(params.min_pairs) +
                             " are needed): are they scans of the same face?");
  };
  std::vector<Pair> pairs = PairUp(outside, baseline, result.transform, params.max_pair_mm);
  check_pairs(pairs);
  auto finish = [&] {
    std::tie(result.rms_mm, result.pairs) = InlierRms(pairs, params.huber_mm);
    return result;
  };
  if (!params.register_rigidly) return finish();

  double last_rotation_deg = 0.0, last_translation_mm = 0.0;
  for (int iteration = 1; iteration <= params.max_iterations; ++iteration) {
    // Linearise about the pairs' centroid: x -> R (x - c) + c + t with
    // R = I + [w]x; the plane distance changes by (x - c) x n . w + n . t.
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Pair& pair : pairs) centroid += pair.point;
    centroid /= static_cast<double>(pairs.size());
    Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> gradient = Eigen::Matrix<double, 6, 1>::Zero();
    const double limit = InlierLimit(pairs, params.huber_mm);
    for (const Pair& pair : pairs) {
      if (std::abs(pair.distance) > limit) continue;
      Eigen::Matrix<double, 6, 1> row;
      row.head<3>() = (pair.point - centroid).cross(pair.normal);
      row.tail<3>() = pair.normal;
      const double magnitude = std::abs(pair.distance);
      const double weight = magnitude <= params.huber_mm ? 1.0 : params.huber_mm / magnitude;
      normal += weight * row * row.transpose();
      gradient += weight * pair.distance * row;
    }
    // Rotation columns scale with the lever arm: compare the blocks in
    // like units before judging degeneracy.
    Eigen::Matrix<double, 6, 1> scale = normal.diagonal().cwiseSqrt();
    for (int k = 0; k < 6; ++k) scale[k] = scale[k] > 0.0 ? 1.0 / scale[k] : 1.0;
    const Eigen::Matrix<double, 6, 6> scaled = scale.asDiagonal() * normal * scale.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(scaled);
    if (eigen.eigenvalues()[0] < kDegenerateRatio * eigen.eigenvalues()[5])
      throw MeasurementError(
          "baseline: the surface outside the region does not fix a rigid motion (it is too "
          "close to a plane, a cylinder or a sphere); register the scans some other way or "
          "measure against a ring reference");
    const Eigen::Matrix<double, 6, 1> step =
        scale.asDiagonal() * scaled.ldlt().solve(-(scale.asDiagonal() * gradient));
    const Eigen::Vector3d w = step.head<3>();
    const double angle = w.norm();
    Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
    if (angle > 0.0) increment.linear() = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
    increment.translation() = centroid - increment.linear() * centroid + step.tail<3>();
    result.transform = increment * result.transform;
    result.iterations = iteration;
    last_rotation_deg = angle * 180.0 / std::numbers::pi;
    last_translation_mm = step.tail<3>().norm();
    pairs = PairUp(outside, baseline, result.transform, params.max_pair_mm);
    check_pairs(pairs);
    if (last_rotation_deg < params.converged_rotation_deg &&
        last_translation_mm < params.converged_translation_mm)
      return finish();
  }
  throw MeasurementError("baseline: the registration did not converge in " +
                         std::to_string(params.max_iterations) + " steps (last step " +
                         std::to_string(last_rotation_deg) + " deg, " +
                         std::to_string(last_translation_mm) + " mm)");
}

}  // namespace bsls::measurement
