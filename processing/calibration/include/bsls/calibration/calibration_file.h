// The calibration file of one side: a versioned, human-readable YAML record
// of a SideCalibration (side_calibration.h) that reconstruction loads.
//
// Layout (format "bsls-calibration", version kCalibrationFormatVersion; a
// full example is in docs/calibration.md):
//   format, format_version, software_version, side, image {width, height},
//   manifest_sha256, pattern {lines, rows, stroke_width}, target {rows, cols,
//   pitch_mm, square_mm},
//   camera {intrinsics, pose, report, views},
//   projector {parallel_plane, perspective_plane, matrix (optional), pose},
//   reference {ray (optional), crosses, screens (q offsets)},
//   uncertainty {stripe_centre_px, target_point_px, plane_mm}.
// Units are in the key names or as in side_calibration.h: world mm, camera
// pixels, projector slide units d; rotations are row-major world -> device.
// Numbers are written as the shortest text that reads back as the same
// double, so a load gives back the saved values exactly.
//
// Not stored (empty or default after loading): SideCalibration::diagnostics,
// the per-point `inlier` flags of the fit reports and the linear stages of
// the camera and projector reports (`dlt`, `tsai`, `tsai_failure`).
//
// Thread-safety: pure functions of their arguments (and the file).
#ifndef BSLS_CALIBRATION_CALIBRATION_FILE_H_
#define BSLS_CALIBRATION_CALIBRATION_FILE_H_

#include <filesystem>
#include <string>

#include "bsls/calibration/calibration_header.h"
#include "bsls/calibration/side_calibration.h"

namespace bsls::calibration {

// kCalibrationFormatName, kCalibrationFormatVersion and CalibrationFileError
// are calibration_header.h's.

// A loaded calibration file: the calibration and who wrote it.
struct CalibrationRecord {
  SideCalibration calibration;
  std::string software_version;
  int format_version = kCalibrationFormatVersion;
};

// The YAML text of a calibration; software_version is recorded as given
// (the CLI passes BSLS_VERSION).
std::string CalibrationToYaml(const SideCalibration& calibration,
                              const std::string& software_version);

// Parses the YAML text of a calibration file; `name` stands for the file in
// error messages. Throws CalibrationFileError.
CalibrationRecord CalibrationFromYaml(const std::string& text, const std::string& name);

// Writes the file atomically (temporary file, fsync, rename): a reader sees
// the old file or the whole new one, never part. Throws OutputError
// naming the file.
void SaveCalibration(const std::filesystem::path& path, const SideCalibration& calibration,
                     const std::string& software_version);

// Reads and checks a calibration file. Throws CalibrationFileError naming the
// file and the reason (io errors included).
CalibrationRecord LoadCalibration(const std::filesystem::path& path);

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_CALIBRATION_FILE_H_
