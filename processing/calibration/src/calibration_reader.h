// Private to the calibration libraries: reads nodes of a calibration file,
// naming the file and the key path in every error (CalibrationFileError).
// The head (calibration_header.cpp) and the body (calibration_file.cpp) are
// read through it, so their errors read alike.
#ifndef BSLS_CALIBRATION_SRC_CALIBRATION_READER_H_
#define BSLS_CALIBRATION_SRC_CALIBRATION_READER_H_

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

#include "bsls/calibration/calibration_header.h"

namespace bsls::calibration {

class CalibrationReader {
 public:
  // Errors name the file `name`.
  explicit CalibrationReader(std::string name) : name_(std::move(name)) {}

  // Throws CalibrationFileError "<name>: <where>: <why>".
  [[noreturn]] void Fail(const std::string& where, const std::string& why) const {
    throw CalibrationFileError(name_ + ": " + (where.empty() ? "" : where + ": ") + why);
  }

  // node[key] (at `where`), which must be there, and a mapping when `map`.
  YAML::Node Child(const YAML::Node& node, const std::string& key, const std::string& where,
                   bool map = true) const {
    const std::string path = where.empty() ? key : where + "." + key;
    // A list item written as a value, or a value where a mapping belongs:
    // yaml-cpp's operator[] would throw its own BadSubscript.
    if (!node.IsMap()) Fail("", "'" + where + "' must be a mapping with '" + key + "'");
    const YAML::Node child = node[key];
    if (!child) Fail("", "missing key '" + path + "'");
    if (map && !child.IsMap()) Fail("", "'" + path + "' must be a mapping");
    return child;
  }

  // The scalar node[key] as a T (a finite number for floating-point T).
  template <typename T>
  T Get(const YAML::Node& node, const std::string& key, const std::string& where) const {
    const YAML::Node child = Child(node, key, where, false);
    const std::string path = where.empty() ? key : where + "." + key;
    if (!child.IsScalar()) Fail("", "'" + path + "' must be a " + TypeName<T>());
    T value{};
    try {
      value = child.as<T>();
    } catch (const YAML::Exception&) {
      Fail("", "'" + path + "' must be a " + TypeName<T>() + ", not '" + child.Scalar() + "'");
    }
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(value)) Fail("", "'" + path + "' is not a finite number");
    }
    return value;
  }

 private:
  template <typename T>
  static std::string TypeName() {
    if constexpr (std::is_same_v<T, bool>) return "boolean";
    if constexpr (std::is_integral_v<T>) return "whole number";
    if constexpr (std::is_floating_point_v<T>) return "number";
    return "string";
  }

  std::string name_;
};

}  // namespace bsls::calibration

#endif  // BSLS_CALIBRATION_SRC_CALIBRATION_READER_H_
