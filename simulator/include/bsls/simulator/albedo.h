// Surface reflectance (albedo) of the simulated scene as a function of world
// position: a smooth low-frequency variation around a base value plus dark
// elliptical patches with soft edges (eyebrow-like regions, thesis 7.1:
// "poor contrast level from different skin colour and any hair on the face").
//
// Frame and units: world frame of contracts section 3, millimetres. Patches are
// ellipses or rectangles (the squares of the calibration target, thesis 6.1)
// in the xy plane painted along z onto whatever surface lies there.
// Albedo is a fraction of light reflected, in [0, 1].
//
// Thread-safety: AlbedoField is immutable; At() may be called concurrently.
#ifndef BSLS_SIMULATOR_ALBEDO_H_
#define BSLS_SIMULATOR_ALBEDO_H_

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace bsls::simulator {

// Outline of an AlbedoPatch.
enum class PatchShape {
  kEllipse,    // semi-axes as given
  kRectangle,  // sides 2 x semi_axis_x_mm by 2 x semi_axis_y_mm
};

// A dark (or bright) elliptical or rectangular patch.
struct AlbedoPatch {
  Eigen::Vector2d centre_xy_mm{0.0, 0.0};  // world x, y of the centre
  double semi_axis_x_mm = 20.0;            // semi-axis along the (rotated) x direction, > 0
  double semi_axis_y_mm = 5.0;             // semi-axis along the (rotated) y direction, > 0
  double rotation_deg = 0.0;               // patch rotation, from +x towards +y
  double albedo = 0.3;                     // albedo inside the patch, in [0, 1]
  double edge_mm = 3.0;                    // width of the soft edge (smoothstep), >= 0; 0 = sharp
  PatchShape shape = PatchShape::kEllipse;
};

// Parameters of an AlbedoField.
struct AlbedoParams {
  double base = 0.8;            // mean albedo outside patches, in (0, 1]
  double variation = 0.1;       // smooth variation stays within base * (1 +- variation), [0, 1)
  double wavelength_mm = 60.0;  // typical wavelength of the smooth variation, > 0
  std::uint32_t seed = 1;       // seeds the directions and phases of the variation
  std::vector<AlbedoPatch> patches;  // applied in order, later ones on top

  // True when every field is in range; otherwise names the field and the reason.
  bool IsValid(std::string* error) const;
};

// Albedo as a function of world position; deterministic given the params.
class AlbedoField {
 public:
  // Default params: base 0.8, +-10 % variation, no patches.
  AlbedoField();
  // Throws std::invalid_argument when `params` is not valid.
  explicit AlbedoField(const AlbedoParams& params);

  // Albedo in [0, 1] at a world point (mm).
  double At(const Eigen::Vector3d& world) const;
  // The params it was built from.
  const AlbedoParams& params() const { return params_; }

 private:
  struct Wave {
    Eigen::Vector3d k;  // wave vector, rad/mm
    double phase = 0.0;
    double weight = 0.0;  // weights sum to 1
  };
  struct PreparedPatch {
    AlbedoPatch patch;
    double cos_r = 1.0, sin_r = 0.0;
  };
  AlbedoParams params_;
  std::vector<Wave> waves_;
  std::vector<PreparedPatch> patches_;
};

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_ALBEDO_H_
