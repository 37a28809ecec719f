#include "bsls/geometry/pinhole_model.h"

#include <Eigen/Geometry>
#include <cmath>

namespace bsls::geometry {

std::optional<Pose> Pose::LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                                 const Eigen::Vector3d& up) {
  const Eigen::Vector3d forward = target - eye;
  if (forward.norm() < 1e-12) return std::nullopt;
  const Eigen::Vector3d z = forward.normalized();
  // Device y points down in the image, i.e. against `up`.
  Eigen::Vector3d x = z.cross(up);
  if (x.norm() < 1e-9) return std::nullopt;
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Pose pose;
  pose.rotation.row(0) = x.transpose();
  pose.rotation.row(1) = y.transpose();
  pose.rotation.row(2) = z.transpose();
  pose.translation = -pose.rotation * eye;
  return pose;
}

bool Intrinsics::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (!(fx > 0.0) || !(fy > 0.0)) return fail("focal lengths must be positive");
  if (!std::isfinite(cx) || !std::isfinite(cy)) return fail("principal point is not finite");
  if (!std::isfinite(k1) || !std::isfinite(k2)) return fail("distortion is not finite");
  return true;
}

PinholeModel::PinholeModel(const Intrinsics& intrinsics, const Pose& pose)
    : intrinsics_(intrinsics), pose_(pose) {}

Eigen::Vector2d PinholeModel::Distort(const Eigen::Vector2d& n) const {
  const double r2 = n.squaredNorm();
  const double scale = 1.0 + intrinsics_.k1 * r2 + intrinsics_.k2 * r2 * r2;
  const Eigen::Vector2d d = n * scale;
  return {intrinsics_.fx * d.x() + intrinsics_.cx, intrinsics_.fy * d.y() + intrinsics_.cy};
}

std::optional<Eigen::Vector2d> PinholeModel::Project(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d dev = pose_.rotation * world + pose_.translation;
  if (dev.z() <= 1e-9) return std::nullopt;
  return Distort({dev.x() / dev.z(), dev.y() / dev.z()});
}

Eigen::Vector2d PinholeModel::Undistort(const Eigen::Vector2d& image) const {
  const Eigen::Vector2d d{(image.x() - intrinsics_.cx) / intrinsics_.fx,
                          (image.y() - intrinsics_.cy) / intrinsics_.fy};
  if (intrinsics_.k1 == 0.0 && intrinsics_.k2 == 0.0) return d;
  // Newton iteration on f(n) = n (1 + k1 r^2 + k2 r^4) - d, radially.
  const double rd = d.norm();
  if (rd < 1e-15) return d;
  double r = rd;
  for (int i = 0; i < 50; ++i) {
    const double r2 = r * r;
    const double f = r * (1.0 + intrinsics_.k1 * r2 + intrinsics_.k2 * r2 * r2) - rd;
    const double df = 1.0 + 3.0 * intrinsics_.k1 * r2 + 5.0 * intrinsics_.k2 * r2 * r2;
    const double step = f / df;
    r -= step;
    if (std::abs(step) < 1e-15) break;
  }
  return d * (r / rd);
}

Ray PinholeModel::BackProject(const Eigen::Vector2d& image) const {
  const Eigen::Vector2d n = Undistort(image);
  const Eigen::Vector3d dir_dev(n.x(), n.y(), 1.0);
  Ray ray;
  ray.origin = Centre();
  ray.direction = (pose_.rotation.transpose() * dir_dev).normalized();
  return ray;
}

}  // namespace bsls::geometry
