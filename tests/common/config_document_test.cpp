// The configuration document behind bslsd's and bsls-processd's settings:
// the file with "key.path=value" overrides on top.
#include "bsls/config/config_document.h"

#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

namespace bsls {
namespace {

// The key and message of the ConfigKeyError that `overrides` cause ("" and
// "" when there is none).
std::pair<std::string, std::string> ErrorOf(const std::vector<std::string>& overrides) {
  try {
    (void)LoadConfigDocument(std::nullopt, overrides);
  } catch (const ConfigKeyError& e) {
    return {e.key(), e.what()};
  }
  return {};
}

TEST(ConfigDocument, OverridesMakeTheMappingsTheyNeed) {
  const YAML::Node root = LoadConfigDocument(std::nullopt, {"a.b.c=1", "a.d=[x, y]", "e=~"});
  EXPECT_EQ(root["a"]["b"]["c"].as<int>(), 1);
  EXPECT_EQ(root["a"]["d"].size(), 2u);
  const YAML::Node later = LoadConfigDocument(std::nullopt, {"e=~", "e.f=2"});
  EXPECT_EQ(later["e"]["f"].as<int>(), 2);
}

// Found by the bslsd configuration fuzz target (issue 26): an override
// below a value ("log_level=info" then "log_level.x=1", or a file's scalar)
// made yaml-cpp throw BadSubscript out of LoadConfigDocument, and bslsd,
// which expects ConfigKeyError, ended in std::terminate.
TEST(ConfigDocument, AnOverrideInsideAValueNamesTheKey) {
  auto [key, what] = ErrorOf({"log_level=info", "log_level.x=1"});
  EXPECT_EQ(key, "log_level");
  EXPECT_NE(what.find("is not a mapping: override 'log_level.x=1' cannot set a key inside it"),
            std::string::npos)
      << what;
  std::tie(key, what) = ErrorOf({"a.b=[1, 2]", "a.b.c=3"});
  EXPECT_EQ(key, "a.b") << what;
  std::tie(key, what) = ErrorOf({"a.b.c.d=1"});
  EXPECT_NE(what.find("is not 1 to 3 levels deep"), std::string::npos) << what;
}

}  // namespace
}  // namespace bsls
