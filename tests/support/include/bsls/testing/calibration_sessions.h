// Simulated calibration sessions shared by the side-calibration and
// calibration-file tests and the tests of what uses a calibration. CTest
// runs every test case in its own process, so a rendered session is cached
// on disk (one folder per session kind and build of the simulator, created
// whole by a rename) and rendered only by the first process of any test
// binary that needs it, the others waiting for it under a file lock; each
// process calibrates it once. Rendering a session is most of what these
// tests cost under the sanitizers (13 views of about 10 s each).
#ifndef BSLS_TESTING_CALIBRATION_SESSIONS_H_
#define BSLS_TESTING_CALIBRATION_SESSIONS_H_

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <map>
#include <ostream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "bsls/calibration/manifest.h"
#include "bsls/calibration/side_calibration.h"
#include "bsls/simulator/calibration_session.h"
#include "bsls/testing/build_paths.h"

namespace bsls::calibration::testing {

// The sessions the tests use: fewer views than the default session (render
// time), the thesis rig, target and placement of the simulator's defaults.
enum class SessionKind {
  kLeftNoisy,  // left side, sensor noise sigma 2 grey levels
  kRightClean  // right side, no noise
};

// "left_noisy" / "right_clean" in test listings.
inline void PrintTo(SessionKind kind, std::ostream* os) {
  *os << (kind == SessionKind::kLeftNoisy ? "left_noisy" : "right_clean");
}

inline constexpr double kSessionNoiseSigma = 2.0;  // grey levels, kLeftNoisy

inline pattern::Side SideOf(SessionKind kind) {
  return kind == SessionKind::kLeftNoisy ? pattern::Side::kLeft : pattern::Side::kRight;
}

inline simulator::CalibrationSessionParams SessionParams(SessionKind kind) {
  simulator::CalibrationSessionParams params;
  params.camera_z_mm = {0, 20, 40, 60, 80, 100};
  params.screen_z_mm = {0, 40, 80, 120};
  params.reference_z_mm = {0, 60, 120};
  params.render.noise_sigma = kind == SessionKind::kLeftNoisy ? kSessionNoiseSigma : 0.0;
  params.render.seed = 11;
  return params;
}

// Which build renders the sessions: `tree` names the build tree (a release
// and a sanitizer build keep their own sessions), `build` the simulator
// libraries' modification times and sizes (a rebuilt simulator renders
// afresh). Without the libraries' paths (bsls/testing/build_paths.h): this
// test binary and its build.
struct SessionBuild {
  std::string tree;
  std::string build;
};

inline SessionBuild SimulatorBuild() {
  namespace fs = std::filesystem;
  std::vector<std::string> files = bsls::testing::SimulatorLibraries();
  SessionBuild out;
  std::string joined;
  for (const std::string& file : files) {
    struct stat info {};
    if (::stat(file.c_str(), &info) != 0) {
      files.clear();
      break;
    }
    joined += file + "|";
    out.build += std::to_string(info.st_mtime) + "_" + std::to_string(info.st_size) + "_";
  }
  if (files.empty()) {
    struct stat exe {};
    std::error_code ec;
    out.tree = fs::read_symlink("/proc/self/exe", ec).filename().string();
    out.build = ::stat("/proc/self/exe", &exe) == 0
                    ? std::to_string(exe.st_mtime) + "_" + std::to_string(exe.st_size)
                    : std::to_string(::getpid());
    return out;
  }
  std::ostringstream tree;
  tree << std::hex << std::hash<std::string>{}(joined);
  out.tree = tree.str();
  out.build.pop_back();
  return out;
}

// The folder of a rendered session (its manifest is session.yaml in it).
inline std::filesystem::path SessionFolder(SessionKind kind) {
  namespace fs = std::filesystem;
  static std::map<SessionKind, fs::path> folders;
  if (auto it = folders.find(kind); it != folders.end()) return it->second;
  const SessionBuild build = SimulatorBuild();
  const std::string prefix = std::string("bsls_calibration_session_") + build.tree + "_" +
                             (kind == SessionKind::kLeftNoisy ? "left_noisy_" : "right_clean_");
  const std::string name = prefix + build.build;
  const fs::path folder = fs::path(::testing::TempDir()) / name;
  // One process renders; the others of any test binary wait for it here.
  const std::string lock_path = (fs::path(::testing::TempDir()) / (prefix + "lock")).string();
  const int lock = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (lock >= 0) ::flock(lock, LOCK_EX);
  std::error_code ec;
  if (!fs::is_regular_file(folder / simulator::kSessionManifestName, ec)) {
    const fs::path temp = folder.string() + ".tmp" + std::to_string(::getpid());
    fs::remove_all(temp, ec);
    simulator::WriteCalibrationSession(
        simulator::SimulateCalibrationSession(SideOf(kind), SessionParams(kind)), temp);
    fs::rename(temp, folder, ec);  // without the lock another process may have won
    fs::remove_all(temp, ec);
    // Sessions of earlier builds of this tree are stale.
    for (const auto& entry : fs::directory_iterator(folder.parent_path(), ec)) {
      const std::string other = entry.path().filename().string();
      if (other.rfind(prefix, 0) == 0 && other.find(".tmp") == std::string::npos && other != name &&
          other != prefix + "lock")
        fs::remove_all(entry.path(), ec);
    }
  }
  if (lock >= 0) ::close(lock);  // releases the lock
  folders[kind] = folder;
  return folder;
}

inline const Manifest& SessionManifest(SessionKind kind) {
  static std::map<SessionKind, Manifest> manifests;
  if (auto it = manifests.find(kind); it != manifests.end()) return it->second;
  return manifests[kind] = LoadManifest(SessionFolder(kind) / simulator::kSessionManifestName);
}

// CalibrateSide with default params on the session, once per process.
inline const SideCalibration& SessionCalibration(SessionKind kind) {
  static std::map<SessionKind, SideCalibration> results;
  if (auto it = results.find(kind); it != results.end()) return it->second;
  return results[kind] = CalibrateSide(SessionManifest(kind));
}

}  // namespace bsls::calibration::testing

#endif  // BSLS_TESTING_CALIBRATION_SESSIONS_H_
