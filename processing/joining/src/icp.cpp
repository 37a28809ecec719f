#include "bsls/joining/icp.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace bsls::joining {
namespace {

// The normal equations are degenerate when their smallest eigenvalue is below
// this fraction of the largest (e.g. a straight common line: no roll about it).
constexpr double kMinEigenvalueRatio = 1e-12;
// Pairs of a rigid fit whose spread's second singular value is below this
// fraction of the first are collinear.
constexpr double kCollinearRatio = 1e-6;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

struct Pair {
  Eigen::Vector3d moved;  // T m
  CurvePoint closest;
};

}  // namespace

bool IcpParams::IsValid(std::string* error) const {
  auto fail = [&](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(converged_rotation_deg > 0.0)) return fail("converged_rotation_deg must be > 0");
  if (!(converged_translation_mm > 0.0)) return fail("converged_translation_mm must be > 0");
  if (!(max_correspondence_mm > 0.0)) return fail("max_correspondence_mm must be > 0");
  if (!(trim_fraction >= 0.0 && trim_fraction < 0.5))
    return fail("trim_fraction must be in [0, 0.5)");
  if (!(huber_mm > 0.0)) return fail("huber_mm must be > 0");
  if (!(curve_weight >= 0.0) || !(plane_weight >= 0.0)) return fail("weights must be >= 0");
  if (!(curve_weight + plane_weight > 0.0)) return fail("one of the weights must be > 0");
  if (min_correspondences < 6) return fail("min_correspondences must be >= 6");
  return true;
}

std::optional<Eigen::Isometry3d> RigidFromPairs(const std::vector<Eigen::Vector3d>& source,
                                                const std::vector<Eigen::Vector3d>& target) {
  if (source.size() != target.size() || source.size() < 3) return std::nullopt;
  const double n = static_cast<double>(source.size());
  Eigen::Vector3d cs = Eigen::Vector3d::Zero(), ct = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    cs += source[i] / n;
    ct += target[i] / n;
  }
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i)
    covariance += (target[i] - ct) * (source[i] - cs).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  if (!(svd.singularValues()(1) > kCollinearRatio * svd.singularValues()(0))) return std::nullopt;
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) d(2, 2) = -1.0;
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.linear() = svd.matrixU() * d * svd.matrixV().transpose();
  transform.translation() = ct - transform.linear() * cs;
  return transform;
}

IcpResult AlignToCurve(const StripeCurve& fixed, const std::vector<Eigen::Vector3d>& moving,
                       const Eigen::Isometry3d& initial, const IcpParams& params,
                       const Cancellation& cancel) {
  IcpResult result;
  result.transform = initial;
  const double converged_rotation_rad = params.converged_rotation_deg * std::numbers::pi / 180.0;
  std::vector<Pair> pairs;
  pairs.reserve(moving.size());
  while (result.iterations < params.max_iterations) {
    cancel.ThrowIfRequested("the ICP alignment");
    pairs.clear();
    for (const Eigen::Vector3d& m : moving) {
      const Eigen::Vector3d moved = result.transform * m;
      if (auto closest = fixed.Closest(moved, params.max_correspondence_mm))
        pairs.push_back({moved, *closest});
    }
    // Trimmed: the worst trim_fraction of the pairs is left out.
    std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
      return a.closest.distance_mm < b.closest.distance_mm;
    });
    pairs.resize(static_cast<std::size_t>(
        std::ceil((1.0 - params.trim_fraction) * static_cast<double>(pairs.size()))));
    result.correspondences = static_cast<int>(pairs.size());
    if (result.correspondences < params.min_correspondences) {
      result.failure = std::to_string(result.correspondences) +
                       " point pairs on the common line within " +
                       std::to_string(static_cast<int>(std::lround(params.max_correspondence_mm))) +
                       " mm (need " + std::to_string(params.min_correspondences) + ")";
      return result;
    }
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double squared = 0.0;
    for (const Pair& pair : pairs) {
      centre += pair.moved / static_cast<double>(pairs.size());
      squared += pair.closest.distance_mm * pair.closest.distance_mm;
    }
    result.rms_mm = std::sqrt(squared / static_cast<double>(pairs.size()));
    // Gauss-Newton on the increment (omega, v): x -> x + omega x (x - centre) + v.
    Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> gradient = Eigen::Matrix<double, 6, 1>::Zero();
    for (const Pair& pair : pairs) {
      const double d = pair.closest.distance_mm;
      const double huber = d <= params.huber_mm ? 1.0 : params.huber_mm / d;
      const Eigen::Vector3d residual = pair.moved - pair.closest.point;
      Eigen::Matrix<double, 3, 6> jacobian;
      jacobian << -Skew(pair.moved - centre), Eigen::Matrix3d::Identity();
      if (params.curve_weight > 0.0) {
        const Eigen::Vector3d& t = pair.closest.tangent;
        const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - t * t.transpose();
        const Eigen::Matrix<double, 3, 6> j = across * jacobian;
        const double w = huber * params.curve_weight;
        normal += w * j.transpose() * j;
        gradient += w * j.transpose() * (across * residual);
      }
      const Eigen::Vector3d& n = pair.closest.normal;
      if (params.plane_weight > 0.0 && n.squaredNorm() > 0.0) {
        const Eigen::Matrix<double, 1, 6> j = n.transpose() * jacobian;
        const double w = huber * params.plane_weight;
        normal += w * j.transpose() * j;
        gradient += w * j.transpose() * n.dot(residual);
      }
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(normal);
    const auto& values = eigen.eigenvalues();
    if (!(values(0) > kMinEigenvalueRatio * values(5))) {
      result.failure =
          "the common line does not pin all six degrees of freedom (degenerate system)";
      return result;
    }
    const Eigen::Matrix<double, 6, 1> step = -normal.ldlt().solve(gradient);
    const Eigen::Vector3d omega = step.head<3>();
    const Eigen::Vector3d v = step.tail<3>();
    Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
    if (omega.norm() > 0.0)
      increment.linear() = Eigen::AngleAxisd(omega.norm(), omega.normalized()).toRotationMatrix();
    increment.translation() = centre - increment.linear() * centre + v;
    result.transform = increment * result.transform;
    ++result.iterations;
    if (omega.norm() < converged_rotation_rad && v.norm() < params.converged_translation_mm) {
      result.converged = true;
      return result;
    }
  }
  result.failure = "no convergence in " + std::to_string(params.max_iterations) + " iterations";
  return result;
}

}  // namespace bsls::joining
