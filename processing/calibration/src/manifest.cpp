#include "bsls/calibration/manifest.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>

#include "bsls/common/errors.h"
#include "bsls/common/sha256.h"
#include "bsls/config/bounded_yaml.h"

namespace bsls::calibration {
namespace {

// Reads `key` of `node` as T; throws ManifestError naming the field. A
// `node` that is not a mapping (`target: 5`, a view written as a bare path)
// is a ManifestError too: yaml-cpp's operator[] on a scalar or a sequence
// would throw its own BadSubscript.
template <typename T>
T Required(const YAML::Node& node, const std::string& key, const std::string& where) {
  if (!node.IsMap()) throw ManifestError(where + ": expected a mapping with '" + key + "'");
  const YAML::Node value = node[key];
  if (!value) throw ManifestError(where + ": missing field '" + key + "'");
  try {
    return value.as<T>();
  } catch (const YAML::Exception&) {
    throw ManifestError(where + ": field '" + key + "' has the wrong type");
  }
}

std::vector<ManifestView> Views(const YAML::Node& root, const std::string& key,
                                const std::filesystem::path& folder, const std::string& file,
                                bool required) {
  std::vector<ManifestView> views;
  const YAML::Node list = root[key];
  if (!list) {
    if (required) throw ManifestError(file + ": missing field '" + key + "'");
    return views;
  }
  if (!list.IsSequence()) throw ManifestError(file + ": '" + key + "' must be a list");
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string where = file + ": " + key + "[" + std::to_string(i) + "]";
    ManifestView v;
    const auto image = Required<std::string>(list[i], "image", where);
    v.z_mm = Required<double>(list[i], "z_mm", where);
    if (!std::isfinite(v.z_mm)) throw ManifestError(where + ": z_mm is not a number");
    v.image =
        std::filesystem::path(image).is_absolute() ? std::filesystem::path(image) : folder / image;
    if (!std::filesystem::is_regular_file(v.image))
      throw ManifestError(where + ": image " + v.image.string() + " does not exist");
    views.push_back(std::move(v));
  }
  return views;
}

}  // namespace

Eigen::Vector3d TargetGeometry::SquareCentre(int row, int col, double z_mm) const {
  return {col * pitch_mm, -row * pitch_mm, z_mm};
}

bool TargetGeometry::IsValid(std::string* error) const {
  auto fail = [error](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (rows < 2 || cols < 2 || rows > 100 || cols > 100)
    return fail("target rows and cols must lie in 2..100");
  if (!(pitch_mm > 0) || !(square_mm > 0) || !(square_mm < pitch_mm))
    return fail("target needs 0 < square_mm < pitch_mm");
  return true;
}

// Contracts section 4.
Manifest LoadManifest(const std::filesystem::path& path) {
  const std::string file = path.string();
  Manifest m;
  m.path = path;
  try {
    m.sha256 = Sha256OfFile(file);
  } catch (const InputError& e) {
    throw ManifestError(e.what());
  }
  YAML::Node root;
  try {
    root = LoadBoundedYamlFile(file);
  } catch (const YAML::Exception& e) {
    throw ManifestError(file + ": not valid YAML: " + e.msg + " (line " +
                        std::to_string(e.mark.line + 1) + ")");
  }
  if (!root.IsMap()) throw ManifestError(file + ": not a manifest (expected a mapping)");

  const auto side = Required<std::string>(root, "side", file);
  if (side == "left")
    m.side = pattern::Side::kLeft;
  else if (side == "right")
    m.side = pattern::Side::kRight;
  else
    throw ManifestError(file + ": side must be left or right, not '" + side + "'");

  const YAML::Node target = root["target"];
  if (!target) throw ManifestError(file + ": missing field 'target'");
  m.target.rows = Required<int>(target, "rows", file + ": target");
  m.target.cols = Required<int>(target, "cols", file + ": target");
  m.target.pitch_mm = Required<double>(target, "pitch_mm", file + ": target");
  m.target.square_mm = Required<double>(target, "square_mm", file + ": target");
  std::string why;
  if (!m.target.IsValid(&why)) throw ManifestError(file + ": " + why);

  if (const YAML::Node pat = root["pattern"]) {
    m.pattern.lines = Required<int>(pat, "lines", file + ": pattern");
    m.pattern.rows = Required<int>(pat, "rows", file + ": pattern");
    if (!m.pattern.IsValid(&why)) throw ManifestError(file + ": pattern: " + why);
  }

  const std::filesystem::path folder = path.parent_path();
  m.camera_views = Views(root, "camera_views", folder, file, true);
  m.screen_views = Views(root, "screen_views", folder, file, true);
  m.reference_views = Views(root, "reference_views", folder, file, false);
  std::set<double> depths;
  for (const ManifestView& v : m.camera_views) depths.insert(v.z_mm);
  if (depths.size() < 2)
    throw ManifestError(
        file + ": camera_views need at least two distinct z_mm (the calibration needs depth)");
  if (m.screen_views.empty()) throw ManifestError(file + ": screen_views is empty");
  return m;
}

std::string ManifestToYaml(const Manifest& m, const std::filesystem::path& folder) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "side" << YAML::Value << (m.side == pattern::Side::kLeft ? "left" : "right");
  out << YAML::Key << "target" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "rows" << YAML::Value << m.target.rows;
  out << YAML::Key << "cols" << YAML::Value << m.target.cols;
  out << YAML::Key << "pitch_mm" << YAML::Value << m.target.pitch_mm;
  out << YAML::Key << "square_mm" << YAML::Value << m.target.square_mm;
  out << YAML::EndMap;
  auto views = [&](const char* key, const std::vector<ManifestView>& list) {
    out << YAML::Key << key << YAML::Value << YAML::BeginSeq;
    for (const ManifestView& v : list) {
      out << YAML::Flow << YAML::BeginMap;
      out << YAML::Key << "image" << YAML::Value
          << std::filesystem::relative(v.image, folder).generic_string();
      out << YAML::Key << "z_mm" << YAML::Value << v.z_mm;
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  };
  views("camera_views", m.camera_views);
  views("screen_views", m.screen_views);
  if (!m.reference_views.empty()) views("reference_views", m.reference_views);
  out << YAML::Key << "pattern" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "lines" << YAML::Value << m.pattern.lines;
  out << YAML::Key << "rows" << YAML::Value << m.pattern.rows;
  out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace bsls::calibration
