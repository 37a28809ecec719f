#include "bsls/calibration/calibration_header.h"

#include <fstream>
#include <sstream>
#include <system_error>

#include "bsls/config/bounded_yaml.h"
#include "calibration_reader.h"

namespace bsls::calibration {

std::string ReadCalibrationText(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw CalibrationFileError(name + ": no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CalibrationFileError(name + ": cannot be opened");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw CalibrationFileError(name + ": read error");
  if (text.str().empty()) throw CalibrationFileError(name + ": the file is empty");
  return text.str();
}

YAML::Node ParseCalibrationYaml(const std::string& text, const std::string& name) {
  const CalibrationReader r(name);
  YAML::Node root;
  try {
    root = LoadBoundedYaml(text);
  } catch (const YAML::Exception& e) {
    r.Fail("", "not valid YAML: " + e.msg + " (line " + std::to_string(e.mark.line + 1) + ")");
  }
  if (!root.IsMap()) r.Fail("", "not a calibration file (expected a YAML mapping)");
  return root;
}

CalibrationHeader ReadCalibrationHeader(const YAML::Node& root, const std::string& name) {
  const CalibrationReader r(name);
  const auto format = r.Get<std::string>(root, "format", "");
  if (format != kCalibrationFormatName)
    r.Fail("", "format is '" + format + "', expected '" + kCalibrationFormatName + "'");
  CalibrationHeader header;
  header.format_version = r.Get<int>(root, "format_version", "");
  if (header.format_version != kCalibrationFormatVersion)
    r.Fail("", "format_version " + std::to_string(header.format_version) +
                   " is not supported (this software reads version " +
                   std::to_string(kCalibrationFormatVersion) + ")");
  header.software_version = r.Get<std::string>(root, "software_version", "");
  const auto side = pattern::ParseSide(r.Get<std::string>(root, "side", ""));
  if (!side) r.Fail("side", "must be left or right");
  header.side = *side;
  return header;
}

CalibrationHeader LoadCalibrationHeader(const std::filesystem::path& path) {
  const std::string name = path.string();
  return ReadCalibrationHeader(ParseCalibrationYaml(ReadCalibrationText(path), name), name);
}

}  // namespace bsls::calibration
