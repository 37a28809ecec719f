#include "bsls/testing/build_paths.h"

// The BSLS_BUILD_* macros are set on this file alone (tests/support/CMakeLists.txt).
namespace bsls::testing {

std::filesystem::path TestDataDir() { return BSLS_BUILD_DATA_DIR; }

std::filesystem::path SharedDir() { return BSLS_BUILD_SHARED_DIR; }

std::filesystem::path FuzzSeedsDir() { return BSLS_BUILD_FUZZ_SEEDS_DIR; }

std::string BslsdPath() { return BSLS_BUILD_BSLSD; }

std::string ProcessdPath() { return BSLS_BUILD_PROCESSD; }

std::string RoleProbePath() { return BSLS_BUILD_ROLE_PROBE; }

std::vector<std::string> SimulatorLibraries() {
  std::vector<std::string> out;
  for (const char* file : {BSLS_BUILD_SIMULATOR, BSLS_BUILD_SIMULATOR_SCENE})
    if (*file != '\0') out.emplace_back(file);
  return out;
}

}  // namespace bsls::testing
