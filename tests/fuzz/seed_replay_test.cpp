// Every file of the checked-in seed corpus (tests/fuzz/seeds/<target>/),
// replayed through its parser target exactly as the fuzzer runs it (the
// bytes as a file, then as a grammar recipe), under whatever compiler builds
// the tests: the seeds, the hostile inputs among them, are
// regression tests without clang or libFuzzer. Each must keep the parser's
// contract (parser_targets.h) and take at most kMaxSeconds; a seed named
// valid_* must be accepted (the parser still reads the real files) and one
// named refused_* refused (the hostile inputs the parser must turn away).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "parser_targets.h"

namespace bsls::fuzz {
namespace {

namespace fs = std::filesystem;

// Per seed file: a few milliseconds in a release build; generous for the
// sanitizers and a loaded machine, far below what the unbounded parsers took
// (minutes for the alias bomb, for ever for the PLY count).
constexpr double kMaxSeconds = 5.0;

// Parameterised by the target's name (its seed folder).
class SeedReplay : public ::testing::TestWithParam<std::string> {};

TEST_P(SeedReplay, EverySeedKeepsTheContract) {
  const ParserTarget* found = FindParserTarget(GetParam());
  ASSERT_NE(found, nullptr) << GetParam();
  const ParserTarget& target = *found;
  const fs::path folder = fs::path(SeedsDir()) / target.name;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file()) files.push_back(entry.path());
  ASSERT_FALSE(files.empty()) << "no seeds in " << folder;
  for (const fs::path& file : files) {
    std::ifstream in(file, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const auto start = std::chrono::steady_clock::now();
    const std::string name = file.filename().string();
    try {
      const bool accepted =
          target.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
      if (name.rfind("valid_", 0) == 0) {
        EXPECT_TRUE(accepted) << name << ": " << target.parser << " refused a valid file";
      }
      if (name.rfind("refused_", 0) == 0) {
        EXPECT_FALSE(accepted) << name << ": " << target.parser << " accepted a hostile file";
      }
    } catch (const ContractViolation& e) {
      ADD_FAILURE() << file.filename() << ": " << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << file.filename() << ": " << target.parser << " threw " << e.what();
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, kMaxSeconds) << file.filename() << " took " << seconds << " s";
  }
}

std::vector<std::string> TargetNames() {
  std::vector<std::string> names;
  for (const ParserTarget& t : ParserTargets()) names.emplace_back(t.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Parsers, SeedReplay, ::testing::ValuesIn(TargetNames()),
                         [](const ::testing::TestParamInfo<std::string>& param) {
                           return param.param;
                         });

}  // namespace
}  // namespace bsls::fuzz
