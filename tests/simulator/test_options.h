// Scene options of the simulator tests: the bundled geometry of the source tree.
#ifndef BSLS_TESTS_SIMULATOR_TEST_OPTIONS_H_
#define BSLS_TESTS_SIMULATOR_TEST_OPTIONS_H_

#include <filesystem>

#include "bsls/simulator/scene.h"
#include "bsls/testing/build_paths.h"

namespace bsls::simulator {

inline const std::filesystem::path kDataDir = bsls::testing::TestDataDir();

// Thesis scene options reading the face and bunny from the source tree.
inline ThesisSceneOptions TestOptions() {
  ThesisSceneOptions options;
  options.face.obj_path = kDataDir / "canonical_face_model.obj";
  options.bunny.json_path = kDataDir / "stanford_bunny.json";
  return options;
}

}  // namespace bsls::simulator

#endif  // BSLS_TESTS_SIMULATOR_TEST_OPTIONS_H_
