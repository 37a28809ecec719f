// Pinhole model with radial distortion, shared by cameras and projectors
// (thesis 2.3, eq. 2.14-2.16; distortion as in thesis 6.1, Tsai's k1/k2).
//
// Frames and units:
//   world   millimetres, contracts section 3 (x right, y up, z towards the
//           cameras; z = 0 is the base plane).
//   device  x right, y down, z along the viewing direction; X_dev = R X_w + t.
//   image   for a camera, pixels with the origin at the centre of the top-left
//           pixel; for a projector, slide coordinates (s, t) in line pitches d
//           (bsls/pattern/brick_pattern.h), focal length then in d as well.
// Distortion maps ideal normalised coordinates (x, y) = (X/Z, Y/Z) to
// distorted ones: (x, y) * (1 + k1 r^2 + k2 r^4), r^2 = x^2 + y^2.
//
// Thread-safety: const members are safe to call concurrently.
#ifndef BSLS_GEOMETRY_PINHOLE_MODEL_H_
#define BSLS_GEOMETRY_PINHOLE_MODEL_H_

#include <Eigen/Core>
#include <optional>
#include <string>

namespace bsls::geometry {

// A ray in world coordinates; direction has unit length.
struct Ray {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();

  // The point origin + distance * direction.
  Eigen::Vector3d At(double distance) const { return origin + distance * direction; }
};

// Rigid transform world -> device: X_dev = rotation * X_world + translation.
struct Pose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  // The device centre in world coordinates.
  Eigen::Vector3d Centre() const { return -rotation.transpose() * translation; }
  // A device at `eye` looking at `target`, with image "up" as close to `up`
  // as possible. Fails (nullopt) when eye == target or up is parallel to the view.
  static std::optional<Pose> LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                                    const Eigen::Vector3d& up);
};

struct Intrinsics {
  double fx = 1000.0;  // focal length, image units (pixels or d)
  double fy = 1000.0;
  double cx = 255.5;  // principal point, image units
  double cy = 255.5;
  double k1 = 0.0;  // radial distortion coefficients
  double k2 = 0.0;

  // True when the numbers describe a usable device; otherwise says why.
  bool IsValid(std::string* error) const;
};

class PinholeModel {
 public:
  PinholeModel() = default;
  PinholeModel(const Intrinsics& intrinsics, const Pose& pose);

  const Intrinsics& intrinsics() const { return intrinsics_; }
  const Pose& pose() const { return pose_; }
  // Device centre in world coordinates.
  Eigen::Vector3d Centre() const { return pose_.Centre(); }

  // Image point of a world point, distortion applied; nullopt when the point
  // is not in front of the device.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& world) const;
  // Ideal (undistorted) normalised coordinates of an image point; iterative
  // inversion of the distortion, accurate to 1e-12 for |k| r^2 < 0.3.
  Eigen::Vector2d Undistort(const Eigen::Vector2d& image) const;
  // Distorted image point of ideal normalised coordinates.
  Eigen::Vector2d Distort(const Eigen::Vector2d& normalised) const;
  // World ray through an image point (from the device centre).
  Ray BackProject(const Eigen::Vector2d& image) const;

 private:
  Intrinsics intrinsics_;
  Pose pose_;
};

}  // namespace bsls::geometry

#endif  // BSLS_GEOMETRY_PINHOLE_MODEL_H_
