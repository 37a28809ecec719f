// Where this build tree keeps the data and programs the tests use. The paths
// are compiled into one small source of their own (src/build_paths.cpp)
// rather than onto every test's compile line: an absolute path in a -D
// option changes the command line, and a clone in another folder would
// compile every such file afresh instead of taking it from ccache.
#ifndef BSLS_TESTING_BUILD_PATHS_H_
#define BSLS_TESTING_BUILD_PATHS_H_

#include <filesystem>
#include <string>
#include <vector>

namespace bsls::testing {

// The simulator's bundled geometry in the source tree (simulator/data).
std::filesystem::path TestDataDir();

// The shared data beside the clone (../shared); it may be absent.
std::filesystem::path SharedDir();

// The fuzz targets' seed inputs (tests/fuzz/seeds).
std::filesystem::path FuzzSeedsDir();

// bslsd as this tree builds it; empty when the tree builds no bslsd.
std::string BslsdPath();

// bsls-processd as this tree builds it; empty when the tree builds none.
std::string ProcessdPath();

// The role probe of the daemon's tests; empty when the tree builds none.
std::string RoleProbePath();

// The simulator's libraries as this tree builds them; none without a simulator.
std::vector<std::string> SimulatorLibraries();

}  // namespace bsls::testing

#endif  // BSLS_TESTING_BUILD_PATHS_H_
