// The YAML document behind a service's configuration (bslsd, bsls-processd):
// the file, if any, with "key.path=value" overrides from the command line
// applied on top, and typed reads that name the key of any error. Unknown
// keys are errors, so a typo never silently keeps a default.
//
// Thread-safety: pure functions (and the file).
#ifndef BSLS_CONFIG_CONFIG_DOCUMENT_H_
#define BSLS_CONFIG_CONFIG_DOCUMENT_H_

#include <yaml-cpp/yaml.h>

#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace bsls {

// A configuration that cannot be used: `key` (dotted, or "" for the whole
// file) and the reason; what() is "<key> <reason>".
class ConfigKeyError : public std::runtime_error {
 public:
  ConfigKeyError(std::string key, std::string reason, bool missing_file = false)
      : std::runtime_error(key.empty() ? reason : key + " " + reason),
        key_(std::move(key)),
        missing_file_(missing_file) {}
  const std::string& key() const { return key_; }
  // True when the configuration file itself does not exist.
  bool missing_file() const { return missing_file_; }

 private:
  std::string key_;
  bool missing_file_;
};

// The file at `path` (if given; an empty map otherwise) with each override
// "a.b.c=value" (value in YAML) applied. Throws ConfigKeyError for a missing
// or malformed file or override.
YAML::Node LoadConfigDocument(const std::optional<std::string>& path,
                              const std::vector<std::string>& overrides);

// Throws ConfigKeyError for a key of the map `node` (at `where`) that is not
// in `known`, or when `node` is not a map. An absent node is fine.
void OnlyKeys(const YAML::Node& node, const std::string& where, const std::set<std::string>& known);

// Reads parent[key] into `out` when it is there; ConfigKeyError naming
// "where.key" when it has the wrong type.
template <typename T>
void ReadKey(const YAML::Node& parent, const std::string& where, const char* key, T& out) {
  const YAML::Node node = parent[key];
  if (!node) return;
  try {
    out = node.as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigKeyError(where.empty() ? key : where + "." + key,
                         "has the wrong type ('" + YAML::Dump(node) + "')");
  }
}

// ReadKey, then ConfigKeyError unless min <= out <= max.
template <typename Number>
void ReadKeyInRange(const YAML::Node& parent, const std::string& where, const char* key,
                    Number& out, Number min, Number max) {
  ReadKey(parent, where, key, out);
  if (out < min || out > max) {
    std::ostringstream range;
    range << "is " << out << "; it must be in [" << min << ", " << max << "]";
    throw ConfigKeyError(where.empty() ? key : where + "." + key, range.str());
  }
}

// ReadKeyInRange of each key of `keys` into `object`: each key has `name`,
// `member` (a pointer to a member of Object), `min` and `max` (e.g.
// rpc::Http2LimitKeys()). Keys are read in the order of `keys`.
template <typename Object, typename Keys>
void ReadKeysInRange(const YAML::Node& parent, const std::string& where, const Keys& keys,
                     Object& object) {
  for (const auto& key : keys)
    ReadKeyInRange(parent, where, key.name, object.*(key.member), key.min, key.max);
}

// Writes each key of `keys` (as for ReadKeysInRange) with its value in
// `object` into the open map of `out`, in the order of `keys`.
template <typename Object, typename Keys>
void DumpKeys(YAML::Emitter& out, const Keys& keys, const Object& object) {
  for (const auto& key : keys) out << YAML::Key << key.name << YAML::Value << object.*(key.member);
}

}  // namespace bsls

#endif  // BSLS_CONFIG_CONFIG_DOCUMENT_H_
