#include "point_set_geometry.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>

namespace bsls::calibration::internal {
namespace {

template <int D>
std::pair<Eigen::Matrix<double, D, 1>, double> CentreAndScale(
    const std::vector<Eigen::Matrix<double, D, 1>>& points, double target_mean_distance) {
  Eigen::Matrix<double, D, 1> centre = Eigen::Matrix<double, D, 1>::Zero();
  if (points.empty()) return {centre, 0.0};
  for (const auto& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  double mean = 0.0;
  for (const auto& p : points) mean += (p - centre).norm();
  mean /= static_cast<double>(points.size());
  return {centre, mean > 0.0 ? target_mean_distance / mean : 0.0};
}

}  // namespace

Eigen::Matrix4d Similarity3::Matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() *= scale;
  m.topRightCorner<3, 1>() = -scale * centre;
  return m;
}

Eigen::Matrix3d Similarity2::Matrix() const {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m.topLeftCorner<2, 2>() *= scale;
  m.topRightCorner<2, 1>() = -scale * centre;
  return m;
}

Eigen::Matrix3d Similarity2::Inverse() const {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m.topLeftCorner<2, 2>() /= scale;
  m.topRightCorner<2, 1>() = centre;
  return m;
}

Similarity3 NormalisingSimilarity(const std::vector<Eigen::Vector3d>& points) {
  const auto [centre, scale] = CentreAndScale<3>(points, std::sqrt(3.0));
  return {centre, scale};
}

Similarity2 NormalisingSimilarity(const std::vector<Eigen::Vector2d>& points) {
  const auto [centre, scale] = CentreAndScale<2>(points, std::sqrt(2.0));
  return {centre, scale};
}

double OutOfPlaneRms(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 4) return 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - centre) * (p - centre).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(scatter);
  return std::sqrt(std::max(svd.singularValues()(2), 0.0) / static_cast<double>(points.size()));
}

double RmsSpread(const std::vector<Eigen::Vector3d>& points) {
  if (points.empty()) return 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  double sum = 0.0;
  for (const auto& p : points) sum += (p - centre).squaredNorm();
  return std::sqrt(sum / static_cast<double>(points.size()));
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) d(2, 2) = -1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

std::optional<Eigen::Vector3d> IntersectZPlane(const geometry::Ray& ray, double z_mm) {
  if (std::abs(ray.direction.z()) < 1e-12) return std::nullopt;
  const double distance = (z_mm - ray.origin.z()) / ray.direction.z();
  if (distance < 0.0) return std::nullopt;
  return ray.At(distance);
}

}  // namespace bsls::calibration::internal
