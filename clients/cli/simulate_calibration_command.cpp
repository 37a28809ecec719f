// bsls simulate-calibration: render a whole calibration session of one side
// (target, screen and cross views, manifest, truth) into a folder.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "bsls/common/errors.h"
#include "bsls/simulator/calibration_session.h"
#include "command.h"

namespace bsls::cli {
namespace {

namespace fs = std::filesystem;

struct SimulateCalibrationOptions {
  std::string side;
  std::string output;
  double noise = 2.0;
  unsigned seed = 1;
  int supersampling = 3;
  int rows = 0;  // 0: the default target's (thesis 6.3: 8 x 8 squares, 6.5 mm pitch)
  int cols = 0;
  double pitch_mm = 0.0;
  double square_mm = 0.0;
  bool rig_origin = false;  // square (0, 0) at the rig origin
};

// Writes the session into `folder`. A folder that does not exist yet is
// filled under a temporary name and renamed when complete, so it appears
// whole or not at all; into an existing folder every file is written
// atomically and the manifest last.
// Throws OutputError when `folder` cannot receive a session: checked
// before anything is rendered.
void CheckOutputFolder(const fs::path& folder) {
  std::error_code ec;
  if (fs::exists(folder, ec)) {
    if (!fs::is_directory(folder, ec))
      throw OutputError(folder.string() + ": exists and is not a folder");
    return;
  }
  const fs::path parent = folder.has_parent_path() ? folder.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, ec))
    throw OutputError(folder.string() + ": the parent folder " + parent.string() +
                      " does not exist");
}

fs::path WriteSession(const simulator::CalibrationSession& session, const fs::path& folder) {
  std::error_code ec;
  CheckOutputFolder(folder);
  if (fs::exists(folder, ec)) return simulator::WriteCalibrationSession(session, folder);
  const fs::path parent = folder.has_parent_path() ? folder.parent_path() : fs::path(".");
  const fs::path temp =
      parent / ("." + folder.filename().string() + ".tmp" + std::to_string(::getpid()));
  try {
    simulator::WriteCalibrationSession(session, temp);
    fs::rename(temp, folder);
  } catch (...) {
    fs::remove_all(temp, ec);
    throw;
  }
  if (ec) throw OutputError(folder.string() + ": cannot move the session in place");
  return folder / simulator::kSessionManifestName;
}

void RunSimulateCalibration(const SimulateCalibrationOptions& o) {
  const auto side = pattern::ParseSide(o.side);
  if (!side) throw CommandError(kExitUsage, "--side must be left or right, not '" + o.side + "'");
  simulator::CalibrationSessionParams params;
  params.render.noise_sigma = o.noise;
  params.render.seed = o.seed;
  params.render.supersampling = o.supersampling;
  if (o.rows > 0) params.target.rows = o.rows;
  if (o.cols > 0) params.target.cols = o.cols;
  if (o.pitch_mm > 0.0) params.target.pitch_mm = o.pitch_mm;
  if (o.square_mm > 0.0) params.target.square_mm = o.square_mm;
  if (o.rig_origin) params.target_origin_rig_mm = Eigen::Vector2d::Zero();
  std::string why;
  if (!params.IsValid(&why)) throw CommandError(kExitUsage, why);
  CheckOutputFolder(o.output);
  simulator::CalibrationSession session;
  try {
    session = simulator::SimulateCalibrationSession(*side, params);
  } catch (const std::invalid_argument& e) {
    // The options put the target out of a camera's view.
    throw CommandError(kExitUsage, e.what());
  }
  const fs::path manifest = WriteSession(session, o.output);
  std::printf(
      "%s: %s side, %zu camera, %zu screen and %zu cross views, target %d x %d at %.4g mm, "
      "noise %.1f\n",
      manifest.string().c_str(), o.side.c_str(), session.camera_views.size(),
      session.screen_views.size(), session.reference_views.size(), params.target.rows,
      params.target.cols, params.target.pitch_mm, o.noise);
}

}  // namespace

void AddSimulateCalibrationCommand(CLI::App& app) {
  auto opts = std::make_shared<SimulateCalibrationOptions>();
  CLI::App* cmd = app.add_subcommand(
      "simulate-calibration",
      "Render a calibration session of one side: target, screen and cross views, session.yaml "
      "manifest and truth.json");
  cmd->add_option("--side", opts->side, "left or right")->required();
  cmd->add_option("-o,--output", opts->output, "Output folder (created whole when new)")
      ->required();
  cmd->add_option("--noise", opts->noise, "Sensor noise sigma, grey levels (default 2)")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--seed", opts->seed, "Noise seed (default 1)");
  cmd->add_option("--supersampling", opts->supersampling, "Rays per pixel and axis (default 3)")
      ->check(CLI::Range(1, 8));
  cmd->add_option("--target-rows", opts->rows, "Target squares per column")
      ->check(CLI::Range(2, 100));
  cmd->add_option("--target-cols", opts->cols, "Target squares per row")->check(CLI::Range(2, 100));
  cmd->add_option("--target-pitch", opts->pitch_mm, "Target square pitch, mm")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--target-square", opts->square_mm, "Target square side, mm (< pitch)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--rig-origin", opts->rig_origin,
                "Lay square (0, 0) on the rig origin (default: the grid centred under the rig)");
  cmd->callback([opts] { RunSimulateCalibration(*opts); });
}

}  // namespace bsls::cli
