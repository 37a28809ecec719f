// Surfaces the simulator renders: one small ray-intersection interface and the
// analytic shapes of the thesis test objects (thesis 7.1, Figure 7.2: base
// plane, 45-degree ramp, ball) and a cylinder (randomised scenes,
// random_scene.h). Triangle meshes live in mesh.h.
//
// Frame and units: world frame of contracts section 3, millimetres (x right,
// y up, z towards the cameras and projector, base plane z = 0).
//
// Thread-safety: surfaces are immutable after construction; Intersect() may be
// called concurrently.
#ifndef BSLS_SIMULATOR_SURFACE_H_
#define BSLS_SIMULATOR_SURFACE_H_

#include <Eigen/Core>
#include <optional>
#include <string>

#include "bsls/geometry/pinhole_model.h"

namespace bsls::simulator {

// Intersections closer to the ray origin than this (mm) are ignored.
inline constexpr double kMinHitDistanceMm = 1e-6;

// Where a ray meets a surface.
struct Hit {
  double distance = 0.0;                                        // along the (unit) ray, mm
  Eigen::Vector3d point = Eigen::Vector3d::Zero();              // world, mm
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();            // shading normal, unit
  Eigen::Vector3d geometric_normal = Eigen::Vector3d::UnitZ();  // facet normal, unit
};
// Both normals point to the surface's front side (outside of a solid, the side
// the triangle winding calls front for a mesh) and lie on the same side; they
// are NOT oriented towards the ray. Surfaces are two-sided: a ray from behind
// hits them too.

// A surface a ray can hit.
class Surface {
 public:
  virtual ~Surface() = default;

  // The nearest intersection at distance in (kMinHitDistanceMm, max_distance),
  // or nullopt when there is none. `ray.direction` must have unit length;
  // max_distance may be infinity.
  virtual std::optional<Hit> Intersect(const geometry::Ray& ray, double max_distance) const = 0;

  // A short human-readable name for logs and reports, e.g. "plane z=0".
  virtual std::string Name() const = 0;
};

// An infinite plane.
class PlaneSurface final : public Surface {
 public:
  // The plane through `point` with front-side normal `normal` (any length > 0).
  PlaneSurface(const Eigen::Vector3d& point, const Eigen::Vector3d& normal);
  // The horizontal plane z = z_mm, front side up (+z).
  static PlaneSurface Horizontal(double z_mm);

  // Nearest hit with the plane, both sides.
  std::optional<Hit> Intersect(const geometry::Ray& ray, double max_distance) const override;
  // "plane" with point and normal.
  std::string Name() const override;

 private:
  Eigen::Vector3d point_;
  Eigen::Vector3d normal_;
};

// A planar ramp rising from the base plane (thesis Table 7.1 test object): a
// rectangle whose lower edge (the foot) lies on z = 0 and which rises at
// `slope_deg` in the direction `rise_azimuth_deg`.
struct RampParams {
  Eigen::Vector2d foot_xy_mm{-120.0, 0.0};  // centre of the foot edge, world x, y (mm)
  double rise_azimuth_deg = 0.0;  // direction of ascent in the xy plane, from +x towards +y
  double slope_deg = 45.0;        // angle to the base plane, in (0, 90)
  double run_mm = 150.0;          // horizontal length from foot to top edge, > 0
  double width_mm = 240.0;        // length of the foot edge, > 0

  // True when the numbers describe a ramp; otherwise says which field and why.
  bool IsValid(std::string* error) const;
};

// The ramp of RampParams; front side faces up (away from the base plane).
class RampSurface final : public Surface {
 public:
  // `params` must be valid (throws std::invalid_argument otherwise).
  explicit RampSurface(const RampParams& params);

  // Nearest hit with the ramp rectangle, both sides.
  std::optional<Hit> Intersect(const geometry::Ray& ray, double max_distance) const override;
  // "ramp" with slope and azimuth.
  std::string Name() const override;
  // Height z (mm) of the ramp plane above world (x, y), extended beyond the rectangle.
  double PlaneHeightAt(double x_mm, double y_mm) const;

 private:
  RampParams params_;
  Eigen::Vector3d foot_;      // foot centre, world
  Eigen::Vector3d up_slope_;  // unit, along the slope (rising)
  Eigen::Vector3d across_;    // unit, along the foot edge
  Eigen::Vector3d normal_;    // unit, front side
  double slope_length_ = 0.0;
};

// A sphere, optionally cut by a horizontal plane (thesis Figure 7.2c: a ball
// on the base plane).
struct BallParams {
  Eigen::Vector3d centre_mm{-70.0, 0.0, -15.0};  // world
  double radius_mm = 60.0;                       // > 0
  // Points of the sphere below this height are not part of the surface.
  double cut_below_z_mm = 0.0;

  // True when the numbers describe a ball; otherwise says which field and why.
  bool IsValid(std::string* error) const;
};

// The ball of BallParams; front side is outside.
class BallSurface final : public Surface {
 public:
  // `params` must be valid (throws std::invalid_argument otherwise).
  explicit BallSurface(const BallParams& params);

  // Nearest hit with the (cut) sphere; may be the inside when seen through the cut.
  std::optional<Hit> Intersect(const geometry::Ray& ray, double max_distance) const override;
  // "ball" with centre and radius.
  std::string Name() const override;

 private:
  BallParams params_;
};

// A finite circular cylinder with flat end caps, optionally cut by a
// horizontal plane: a log or a can lying on (or sunk into) the base plane.
struct CylinderParams {
  Eigen::Vector3d centre_mm{-50.0, 0.0, 30.0};  // middle of the axis, world
  Eigen::Vector3d axis{0.0, 1.0, 0.0};          // axis direction, any length > 0
  double radius_mm = 40.0;                      // > 0
  double length_mm = 160.0;                     // along the axis, cap to cap, > 0
  bool caps = true;                             // close both ends with discs
  // Points below this height are not part of the surface.
  double cut_below_z_mm = 0.0;

  // True when the numbers describe a cylinder; otherwise says which field and why.
  bool IsValid(std::string* error) const;
};

// The cylinder of CylinderParams; front side is outside (caps: facing away
// from the middle).
class CylinderSurface final : public Surface {
 public:
  // `params` must be valid (throws std::invalid_argument otherwise).
  explicit CylinderSurface(const CylinderParams& params);

  // Nearest hit with the mantle or a cap (above the cut), both sides.
  std::optional<Hit> Intersect(const geometry::Ray& ray, double max_distance) const override;
  // "cylinder" with centre, axis, radius and length.
  std::string Name() const override;

 private:
  CylinderParams params_;
  Eigen::Vector3d axis_;  // unit
};

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_SURFACE_H_
