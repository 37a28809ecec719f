// Simulated calibration sessions shared by the side-calibration and
// calibration-file tests. CTest runs every test case in its own process, so a
// rendered session is cached on disk (one folder per session kind, test
// binary and its build, created whole by a rename) and rendered only by the first
// process that needs it; each process calibrates it once.
#ifndef BSLS_TESTING_CALIBRATION_SESSIONS_H_
#define BSLS_TESTING_CALIBRATION_SESSIONS_H_

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <ostream>
#include <string>
#include <system_error>

#include "bsls/calibration/manifest.h"
#include "bsls/calibration/side_calibration.h"
#include "bsls/simulator/calibration_session.h"

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

// The folder of a rendered session (its manifest is session.yaml in it).
inline std::filesystem::path SessionFolder(SessionKind kind) {
  namespace fs = std::filesystem;
  static std::map<SessionKind, fs::path> folders;
  if (auto it = folders.find(kind); it != folders.end()) return it->second;
  // Keyed by this binary and its build: a rebuilt simulator renders afresh.
  // Only this binary's earlier builds are cleared below: test binaries of
  // other builds may run beside it and use their own folders.
  struct stat exe {};
  const std::string build = ::stat("/proc/self/exe", &exe) == 0
                                ? std::to_string(exe.st_mtime) + "_" + std::to_string(exe.st_size)
                                : std::to_string(::getpid());
  std::error_code ec;
  const std::string binary = fs::read_symlink("/proc/self/exe", ec).filename().string();
  const std::string name = std::string("bsls_calibration_session_") + binary + "_" +
                           (kind == SessionKind::kLeftNoisy ? "left_noisy_" : "right_clean_") +
                           build;
  const fs::path folder = fs::path(::testing::TempDir()) / name;
  if (!fs::is_regular_file(folder / simulator::kSessionManifestName, ec)) {
    const fs::path temp = folder.string() + ".tmp" + std::to_string(::getpid());
    fs::remove_all(temp, ec);
    simulator::WriteCalibrationSession(
        simulator::SimulateCalibrationSession(SideOf(kind), SessionParams(kind)), temp);
    fs::rename(temp, folder, ec);  // another process may have won: use its folder
    fs::remove_all(temp, ec);
    // Sessions of earlier builds of this binary are stale.
    const std::string prefix = name.substr(0, name.size() - build.size());
    for (const auto& entry : fs::directory_iterator(folder.parent_path(), ec)) {
      const std::string other = entry.path().filename().string();
      if (other.rfind(prefix, 0) == 0 && other.find(".tmp") == std::string::npos && other != name)
        fs::remove_all(entry.path(), ec);
    }
  }
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
