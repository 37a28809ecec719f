// The head of a calibration file (calibration_file.h): its format, format
// version, the software that wrote it and the side it calibrates, read and
// checked without the rest. What a program that only hands calibration files
// on needs (bslsd checks that each of its files is for the side it is
// configured as), without the calibration library and its dependencies.
//
// Layout: a YAML mapping whose first keys are
//   format: bsls-calibration
//   format_version: 1
//   software_version: "..."
//   side: left | right
// (the whole layout is in calibration_file.h and docs/calibration.md).
//
// Errors: CalibrationFileError naming the file and the reason, with the
// same messages as LoadCalibration for the same faults.
//
// Thread-safety: pure functions of their arguments (and the file).
#ifndef BSLS_CALIBRATION_CALIBRATION_HEADER_H_
#define BSLS_CALIBRATION_CALIBRATION_HEADER_H_

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "bsls/pattern/brick_pattern.h"

namespace bsls::calibration {

inline constexpr const char* kCalibrationFormatName = "bsls-calibration";
inline constexpr int kCalibrationFormatVersion = 1;

// A calibration file that cannot be used; what() names the file and the
// reason (another format or version, not YAML, truncated, a missing key, a
// wrong type, a non-finite number, an impossible value).
class CalibrationFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What the head of a calibration file says.
struct CalibrationHeader {
  int format_version = kCalibrationFormatVersion;
  std::string software_version;
  pattern::Side side = pattern::Side::kLeft;
};

// The whole text of the calibration file at `path`. Throws
// CalibrationFileError for a missing, unreadable or empty file.
std::string ReadCalibrationText(const std::filesystem::path& path);

// The YAML mapping of a calibration file's text (parsed within
// YamlLimits); `name` stands for the file in error messages. Throws
// CalibrationFileError when it is not valid YAML or not a mapping.
YAML::Node ParseCalibrationYaml(const std::string& text, const std::string& name);

// The head of the mapping `root` (ParseCalibrationYaml). Throws
// CalibrationFileError for another format, an unsupported version, a missing
// or mistyped key, or a side other than left or right.
CalibrationHeader ReadCalibrationHeader(const YAML::Node& root, const std::string& name);

// ReadCalibrationHeader of the file at `path` (the rest of the file is
// parsed as YAML but not checked).
CalibrationHeader LoadCalibrationHeader(const std::filesystem::path& path);

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_CALIBRATION_HEADER_H_
