// LoadBoundedYaml on what a hostile or careless client sends: aliases
// that make a tree contain itself or grow 8x per level, deep nesting, too
// many nodes, an oversized file; and documents of the project's own shape,
// which load as yaml-cpp loads them.
#include "bsls/config/bounded_yaml.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace bsls {
namespace {

// The message of the ParserException `text` raises, or "" when it loads.
std::string Refusal(const std::string& text, const YamlLimits& limits = {}) {
  try {
    LoadBoundedYaml(text, limits);
  } catch (const YAML::ParserException& e) {
    return e.msg;
  }
  return "";
}

TEST(BoundedYaml, SelfContainingAliasesAreRefused) {
  // Each of these crashed bsls-processd (a recursion over a tree that
  // contains itself) before the shape was checked.
  for (const char* text : {"a: &a [*a]", "&a {k: *a}", "x: &x\n  y: *x\n"})
    EXPECT_NE(Refusal(text).find("aliases"), std::string::npos) << text;
}

TEST(BoundedYaml, AnAliasBombIsRefusedAtItsFirstAlias) {
  // Ten levels of eight references each: 8^10 nodes to visit once loaded.
  std::string text = "l0: &l0 [x, x, x, x, x, x, x, x]\n";
  for (int level = 1; level <= 10; ++level) {
    const std::string prev = "*l" + std::to_string(level - 1);
    text += "l" + std::to_string(level) + ": &l" + std::to_string(level) + " [";
    for (int k = 0; k < 8; ++k) text += (k ? ", " : "") + prev;
    text += "]\n";
  }
  try {
    LoadBoundedYaml(text);
    FAIL() << "loaded";
  } catch (const YAML::ParserException& e) {
    EXPECT_EQ(e.mark.line, 1) << e.msg;  // the second line holds the first alias
  }
}

TEST(BoundedYaml, DepthAndNodeCountAreBounded) {
  const std::string deep = std::string(40, '[') + std::string(40, ']');
  EXPECT_NE(Refusal(deep).find("nested deeper than 32"), std::string::npos);
  EXPECT_EQ(Refusal(std::string(32, '[') + std::string(32, ']')), "");
  // Beyond yaml-cpp's own guard as well: refused, not a crash.
  const std::string very_deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_NE(Refusal(very_deep), "");
  YamlLimits few;
  few.max_nodes = 10;
  EXPECT_NE(Refusal("[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]", few).find("more than 10 nodes"),
            std::string::npos);
  EXPECT_EQ(Refusal("[1, 2, 3, 4, 5, 6, 7, 8]", few), "");
}

TEST(BoundedYaml, ADocumentOfOurOwnShapeLoadsAsYamlCppLoadsIt) {
  const std::string text =
      "side: left\nviews:\n  - kind: target\n    image: target_00.png\n    z_mm: -20.5\n"
      "  - kind: screen\n    image: screen_01.png\n    z_mm: 0\n";
  const YAML::Node bounded = LoadBoundedYaml(text);
  const YAML::Node plain = YAML::Load(text);
  EXPECT_EQ(YAML::Dump(bounded), YAML::Dump(plain));
  EXPECT_EQ(bounded["views"][1]["image"].as<std::string>(), "screen_01.png");
  // Anchors alone (no alias refers to them) are harmless and kept.
  EXPECT_EQ(LoadBoundedYaml("a: &x 3\n")["a"].as<int>(), 3);
}

TEST(BoundedYaml, FilesAreBoundedBeforeTheyAreRead) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "bsls_bounded_yaml_test.yaml";
  {
    std::ofstream out(path);
    out << "key: " << std::string(2000, 'v') << "\n";
  }
  YamlLimits small;
  small.max_bytes = 1000;
  try {
    LoadBoundedYamlFile(path.string(), small);
    FAIL() << "loaded";
  } catch (const YAML::ParserException& e) {
    EXPECT_NE(e.msg.find("more than 1000"), std::string::npos) << e.msg;
  }
  EXPECT_EQ(LoadBoundedYamlFile(path.string())["key"].as<std::string>().size(), 2000u);
  std::filesystem::remove(path);
  EXPECT_THROW(LoadBoundedYamlFile(path.string()), YAML::BadFile);
}

}  // namespace
}  // namespace bsls
