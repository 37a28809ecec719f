// DefaultDataDir() alone: the data folders' absolute paths are on this file's
// compile line only (simulator/CMakeLists.txt), so a clone in another folder
// takes the rest of the simulator from ccache.
#include <cstdlib>
#include <system_error>

#include "bsls/simulator/scene.h"

namespace bsls::simulator {

std::filesystem::path DefaultDataDir() {
  if (const char* env = std::getenv("BSLS_DATA_DIR"); env != nullptr && *env != '\0')
    return std::filesystem::path(env);
  const std::filesystem::path installed(BSLS_DATA_DIR);
  std::error_code ec;
  if (std::filesystem::exists(installed / kFaceFileName, ec)) return installed;
  return std::filesystem::path(BSLS_SOURCE_DATA_DIR);
}

}  // namespace bsls::simulator
