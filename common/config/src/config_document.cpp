#include "bsls/config/config_document.h"

#include <filesystem>

#include "bsls/config/bounded_yaml.h"

namespace bsls {

YAML::Node LoadConfigDocument(const std::optional<std::string>& path,
                              const std::vector<std::string>& overrides) {
  YAML::Node root;
  if (path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(*path, ec))
      throw ConfigKeyError("", "configuration file " + *path + " does not exist", true);
    try {
      root = LoadBoundedYamlFile(*path);
    } catch (const YAML::Exception& e) {
      throw ConfigKeyError("", "configuration file " + *path + " is not valid YAML: " + e.what());
    }
  }
  if (!root || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap())
    throw ConfigKeyError("", "configuration file " + path.value_or("") + " is not a mapping");
  for (const std::string& assignment : overrides) {
    const std::size_t equals = assignment.find('=');
    if (equals == std::string::npos || equals == 0)
      throw ConfigKeyError("", "override '" + assignment + "' is not of the form key.path=value");
    const std::string key = assignment.substr(0, equals);
    YAML::Node value;
    try {
      value = LoadBoundedYaml(assignment.substr(equals + 1));
    } catch (const YAML::Exception&) {
      throw ConfigKeyError("", "override '" + assignment + "': the value is not valid YAML");
    }
    std::vector<std::string> parts;
    std::stringstream stream(key);
    for (std::string part; std::getline(stream, part, '.');) parts.push_back(part);
    // Every level above the last must be a mapping (or absent, then made
    // one): yaml-cpp's operator[] on a value or a list throws its own
    // BadSubscript, which reached bslsd's main uncaught. Read through const
    // nodes, which add nothing to the tree (and never assign one node to
    // another: yaml-cpp would rebind the tree's own node).
    const auto check = [&](const YAML::Node& node, const std::string& prefix) {
      if (node && !node.IsNull() && !node.IsMap())
        throw ConfigKeyError(
            prefix, "is not a mapping: override '" + assignment + "' cannot set a key inside it");
    };
    const YAML::Node& readonly = root;
    if (parts.size() >= 2) {
      const YAML::Node first = readonly[parts[0]];
      check(first, parts[0]);
      if (parts.size() >= 3 && first && first.IsMap())
        check(first[parts[1]], parts[0] + "." + parts[1]);
    }
    // yaml-cpp nodes are references: index the path in one expression.
    if (parts.size() == 1) {
      root[parts[0]] = value;
    } else if (parts.size() == 2) {
      root[parts[0]][parts[1]] = value;
    } else if (parts.size() == 3) {
      root[parts[0]][parts[1]][parts[2]] = value;
    } else {
      throw ConfigKeyError("", "override key '" + key + "' is not 1 to 3 levels deep");
    }
  }
  return root;
}

void OnlyKeys(const YAML::Node& node, const std::string& where,
              const std::set<std::string>& known) {
  if (!node) return;
  if (!node.IsMap()) throw ConfigKeyError(where, "must be a mapping");
  for (const auto& item : node) {
    const std::string key = item.first.as<std::string>();
    if (!known.count(key)) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      throw ConfigKeyError(where.empty() ? key : where + "." + key,
                           "is not a known key (known: " + list + ")");
    }
  }
}

}  // namespace bsls
