// Lumps and cavities added to any surface (thesis 7.2, Figures 7.12-7.13,
// Tables 7.3-7.4: a lump on the cheek 15 mm high, cavities on the forehead and
// cheek 15 mm and 10 mm deep), with their exact ground truth.
//
// A lesion is a round, smooth displacement along world z of the surface under
// it: at horizontal distance r from its centre the surface moves by
//   h(r) = H                                        r <= r0 (flat top)
//   h(r) = H * (1 + cos(pi (r - r0) / (R - r0))) / 2   r0 < r < R (cosine skirt)
//   h(r) = 0                                        r >= R
// H > 0 raises a lump, H < 0 sinks a cavity. With r0 = 0 it is a cosine bell.
// Because the displacement is along z, the height of a lesion point above
// the undisturbed surface is exactly h and the volume between the two is
// exactly the integral of h over the disc, whatever the surface under it.
//
// Frame and units: world frame of contracts section 3, millimetres.
//
// Thread-safety: LesionSurface is immutable after construction; Intersect()
// may be called concurrently if the base surface allows it.
#ifndef BSLS_SIMULATOR_LESION_H_
#define BSLS_SIMULATOR_LESION_H_

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bsls/simulator/surface.h"

namespace bsls::simulator {

// One lump (height_mm > 0) or cavity (height_mm < 0).
struct LesionParams {
  Eigen::Vector2d centre_xy_mm{-40.0, -35.0};  // world x, y of the centre (mm)
  double height_mm = 15.0;                     // H: signed peak displacement along +z, |H| > 0
  double radius_mm = 30.0;                     // R: outer radius of the footprint, > 0
  double top_radius_mm = 8.0;                  // r0: radius of the flat top, in [0, R)

  // True when the numbers describe a lesion; otherwise names the field and why.
  bool IsValid(std::string* error) const;

  // h at horizontal distance r (mm) from the centre.
  double ProfileAt(double r_mm) const;
  // Displacement h at world (x, y), mm.
  double DisplacementAt(const Eigen::Vector2d& xy_mm) const;
  // Gradient (dh/dx, dh/dy) at world (x, y), dimensionless.
  Eigen::Vector2d GradientAt(const Eigen::Vector2d& xy_mm) const;
  // Radius (mm) of the disc where |h| >= fraction * |H|, fraction in (0, 1].
  double RadiusAtLevel(double fraction) const;
  // Exact signed volume between the displaced and the undisturbed surface, mm^3:
  // pi H (r0^2 + w^2/2 + r0 w - 2 w^2/pi^2), w = R - r0.
  double Volume() const;
};

// Ground truth of one lesion on its base surface.
struct LesionTruth {
  double peak_mm = 0.0;          // signed H, along z above (below) the undisturbed surface
  double volume_mm3 = 0.0;       // signed, exact
  double level_fraction = 0.5;   // the level the areas below refer to, fraction of |H|
  double level_radius_mm = 0.0;  // radius of the disc where |h| >= level_fraction |H|
  // Area of the undisturbed surface over that disc (mm^2, numerical).
  double area_on_base_mm2 = 0.0;
  // Area of the displaced surface over that disc (mm^2, numerical).
  double area_on_lesion_mm2 = 0.0;
};

// `base` with lesions pressed into it along z. The base must be a height field
// (one surface point per vertical line) over every lesion's disc; lesion
// discs must not overlap.
class LesionSurface final : public Surface {
 public:
  // Throws std::invalid_argument for a null base, an invalid lesion or two
  // overlapping lesion discs (the message names the lesion index).
  LesionSurface(std::shared_ptr<const Surface> base, std::vector<LesionParams> lesions);

  // Nearest hit with the displaced surface: the base outside the lesion
  // discs; inside them the ray is marched (steps of kLesionMarchStepMm
  // horizontally) and the crossing refined by bisection. Normals are those of
  // the displaced height field, on the base normal's side.
  std::optional<Hit> Intersect(const geometry::Ray& ray, double max_distance) const override;
  // The base's name with "+ N lesions".
  std::string Name() const override;

  // Height z (mm) of the undisturbed base surface at (x, y): the highest hit
  // of a vertical ray; nullopt when no surface lies under (x, y).
  std::optional<double> BaseHeightAt(const Eigen::Vector2d& xy_mm) const;
  // Height z (mm) of the displaced surface at (x, y); nullopt as above.
  std::optional<double> HeightAt(const Eigen::Vector2d& xy_mm) const;
  // Total displacement at (x, y) (mm; 0 outside every lesion).
  double DisplacementAt(const Eigen::Vector2d& xy_mm) const;

  // Ground truth of lesion `index`: exact peak and volume; areas over the
  // disc |h| >= level_fraction |H| integrated on a polar grid of `step_mm`
  // (midpoint rule; the slopes of the base come from its hit normals).
  // Throws std::invalid_argument for a bad index, fraction or step, and
  // std::runtime_error when part of the disc has no base surface under it.
  LesionTruth Truth(std::size_t index, double level_fraction = 0.5, double step_mm = 0.2) const;

  const std::vector<LesionParams>& lesions() const { return lesions_; }
  const Surface& base() const { return *base_; }

 private:
  // Base hit straight below (x, y) from above: position and normal.
  std::optional<Hit> BaseBelow(const Eigen::Vector2d& xy_mm) const;

  std::shared_ptr<const Surface> base_;
  std::vector<LesionParams> lesions_;
};

// Horizontal step (mm) with which rays are marched through a lesion's disc.
inline constexpr double kLesionMarchStepMm = 0.25;

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_LESION_H_
