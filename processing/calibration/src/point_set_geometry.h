// Geometry of point sets used by the linear calibration solvers: Hartley
// normalisation, planarity, the nearest rotation and ray/plane intersection.
// Internal to bsls_calibration. Units are those of the points given.
//
// Thread-safety: pure functions of their arguments.
#ifndef BSLS_CALIBRATION_SRC_POINT_SET_GEOMETRY_H_
#define BSLS_CALIBRATION_SRC_POINT_SET_GEOMETRY_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "bsls/geometry/pinhole_model.h"

namespace bsls::calibration::internal {

// x -> scale * (x - centre), as a homogeneous matrix too.
struct Similarity3 {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double scale = 1.0;
  Eigen::Vector3d Apply(const Eigen::Vector3d& x) const { return scale * (x - centre); }
  Eigen::Matrix4d Matrix() const;
};

struct Similarity2 {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double scale = 1.0;
  Eigen::Vector2d Apply(const Eigen::Vector2d& x) const { return scale * (x - centre); }
  Eigen::Matrix3d Matrix() const;
  Eigen::Matrix3d Inverse() const;
};

// Hartley normalisation: centroid to the origin, mean distance sqrt(3) (3-D)
// or sqrt(2) (2-D). scale is 0 when all points coincide.
Similarity3 NormalisingSimilarity(const std::vector<Eigen::Vector3d>& points);
Similarity2 NormalisingSimilarity(const std::vector<Eigen::Vector2d>& points);

// RMS distance of the points from their best-fitting (total least squares) plane.
double OutOfPlaneRms(const std::vector<Eigen::Vector3d>& points);
// RMS distance of the points from their centroid.
double RmsSpread(const std::vector<Eigen::Vector3d>& points);

// The rotation closest (Frobenius) to m, by SVD; det = +1.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m);

// Where the ray meets the plane z = z_mm; nullopt when parallel to it or behind the origin.
std::optional<Eigen::Vector3d> IntersectZPlane(const geometry::Ray& ray, double z_mm);

}  // namespace bsls::calibration::internal

#endif  // BSLS_CALIBRATION_SRC_POINT_SET_GEOMETRY_H_
