// The calibration session manifest (contracts section 4): which images of
// one side's session show the target, the screen with the brick slide and
// the screen with slide 1, and at which offset z of the target along +z.
//
// Units: millimetres. Paths in the file are relative to the manifest's
// folder; Manifest holds them resolved.
#ifndef BSLS_CALIBRATION_MANIFEST_H_
#define BSLS_CALIBRATION_MANIFEST_H_

#include <Eigen/Core>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "bsls/pattern/brick_pattern.h"

namespace bsls::calibration {

// A manifest that cannot be used; what() names the file and the reason.
class ManifestError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The planar target of contracts section 3: rows x cols dark squares.
struct TargetGeometry {
  int rows = 8;
  int cols = 8;
  double pitch_mm = 6.5;   // centre-to-centre
  double square_mm = 4.0;  // side of a square, < pitch_mm

  // World position (mm) of the centre of square (row, col) with the target
  // at offset z_mm: (col * pitch, -row * pitch, z).
  Eigen::Vector3d SquareCentre(int row, int col, double z_mm) const;
  // True when the numbers describe a usable target; otherwise says why.
  bool IsValid(std::string* error) const;
};

struct ManifestView {
  std::filesystem::path image;  // resolved against the manifest's folder
  double z_mm = 0.0;
};

struct Manifest {
  pattern::Side side = pattern::Side::kLeft;
  TargetGeometry target;
  std::vector<ManifestView> camera_views;     // the target at each z
  std::vector<ManifestView> screen_views;     // blank plane with the side's brick slide
  std::vector<ManifestView> reference_views;  // blank plane with slide 1 (optional)
  pattern::PatternSpec pattern;               // N (lines) and M (rows)
  std::filesystem::path path;                 // the manifest file itself
  std::string sha256;                         // of the manifest file's bytes
};

// Reads and checks a manifest. Throws ManifestError naming the file and the
// reason for an unreadable or malformed file, a missing or unknown field, an
// invalid target or pattern, fewer than two camera views at distinct z (the
// camera calibration needs depth), no screen view, or a listed image that
// does not exist.
Manifest LoadManifest(const std::filesystem::path& path);

// The manifest as YAML text in the contracts' layout, image paths made
// relative to `folder`.
std::string ManifestToYaml(const Manifest& manifest, const std::filesystem::path& folder);

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_MANIFEST_H_
