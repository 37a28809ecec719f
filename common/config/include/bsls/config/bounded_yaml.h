// YAML from outside the process (calibration manifests, calibration files,
// service configurations, requests) parsed into yaml-cpp's node tree only
// after its shape is checked, so that a few hundred bytes cannot make a
// tree that never ends or grows with every level.
//
// What is refused, and why:
//   * aliases (`*name`): no file this project reads needs them, and yaml-cpp
//     shares an aliased node, so `a: &a [*a]` is a tree that contains itself
//     and ten nested aliases of eight references each are 8^10 nodes to visit;
//   * nesting deeper than max_depth (this project's documents are 4 deep);
//   * more than max_nodes nodes, and files over max_bytes.
// yaml-cpp's own parser stops at 2000 levels (DeepRecursion); these checks
// run on its event stream first, before any tree is built.
//
// Errors: YAML::ParserException at the offending place (its mark and msg),
// which every reader already reports as "not valid YAML: <msg> (line N)";
// YAML::BadFile for a file that cannot be read.
//
// Thread-safety: pure functions (and the file).
#ifndef BSLS_CONFIG_BOUNDED_YAML_H_
#define BSLS_CONFIG_BOUNDED_YAML_H_

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

namespace bsls {

struct YamlLimits {
  int max_depth = 32;                 // nested sequences and mappings
  std::size_t max_nodes = 1000000;    // scalars, sequences and mappings (keys included)
  std::size_t max_bytes = 16u << 20;  // a file's size
};

// `text` as yaml-cpp's YAML::Load gives it (the first document), once every
// document in it passes `limits`; throws YAML::ParserException otherwise.
YAML::Node LoadBoundedYaml(const std::string& text, const YamlLimits& limits = {});

// LoadBoundedYaml of the file at `path`, refused before it is read when it
// is larger than limits.max_bytes.
YAML::Node LoadBoundedYamlFile(const std::string& path, const YamlLimits& limits = {});

}  // namespace bsls

#endif  // BSLS_CONFIG_BOUNDED_YAML_H_
