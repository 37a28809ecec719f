// bsls calibrate: calibrate one side (camera, light planes, projector) from a
// session manifest (contracts section 4) and write its calibration file.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "bsls/calibration/calibration_file.h"
#include "bsls/calibration/calibration_report.h"
#include "bsls/calibration/manifest.h"
#include "bsls/calibration/side_calibration.h"
#include "bsls/common/atomic_file.h"
#include "command.h"
#include "daemon_connection.h"

namespace bsls::cli {
namespace {

struct CalibrateOptions {
  std::string manifest;
  std::string output;
  std::string report;
  bool quiet = false;
  bool json = false;      // the report on stdout instead of the summary
  ServiceAddress server;  // target empty: calibrated here
};

// One summary line for a view the calibration left out.
void PrintDropped(const std::string& kind, const std::string& image, double z_mm,
                  const std::string& reason) {
  std::printf("dropped %s view %s (z = %g mm): %s\n", kind.c_str(), image.c_str(), z_mm,
              reason.c_str());
}

// The same calibration on the processing service: the manifest and every
// image it names are uploaded; the calibration file and report come back.
void RunCalibrateRemote(const CalibrateOptions& o) {
  namespace fs = std::filesystem;
  calibration::Manifest manifest;
  try {
    manifest = calibration::LoadManifest(o.manifest);  // checks it and that every image exists
  } catch (const calibration::ManifestError& e) {
    throw CommandError(kExitInput, e.what());
  }
  const fs::path folder = fs::weakly_canonical(fs::path(o.manifest).parent_path().empty()
                                                   ? fs::path(".")
                                                   : fs::path(o.manifest).parent_path());
  std::vector<processing::UploadFile> files;
  for (const auto* views :
       {&manifest.camera_views, &manifest.screen_views, &manifest.reference_views})
    for (const calibration::ManifestView& view : *views) {
      const fs::path image = fs::weakly_canonical(view.image);
      const fs::path relative = image.lexically_relative(folder);
      if (relative.empty() || *relative.begin() == "..")
        throw CommandError(kExitInput, o.manifest + ": image " + view.image.string() +
                                           " is outside the manifest's folder; --server uploads "
                                           "only what is inside it");
      files.push_back({relative.generic_string(), ReadInputFile(image.string(), "image")});
    }
  processing::ProcessingClient client = OpenProcessingClient(o.server);
  const processing::WorkOutcome out =
      client.Calibrate(ReadInputFile(o.manifest, "manifest"), files, o.manifest.substr(0, 256),
                       ProgressPrinter(o.quiet));
  CheckWork(out.status, o.manifest, o.server);
  const nlohmann::json report = nlohmann::json::parse(out.files.at("calibration-report.json"));
  if (!o.report.empty()) WriteFileAtomically(o.report, out.files.at("calibration-report.json"));
  WriteFileAtomically(o.output, out.files.at("calibration.yaml"));
  if (o.json) {
    nlohmann::json summary = report;
    summary["calibration_id"] = out.result.calibration_id();
    summary["replica"] = out.result.replica();
    std::cout << summary.dump() << "\n";
    return;
  }
  std::printf("%s: %s side, %d x %d px, id %s (calibrated by %s)\n", o.output.c_str(),
              report.at("side").get<std::string>().c_str(), report.at("width").get<int>(),
              report.at("height").get<int>(), out.result.calibration_id().c_str(),
              out.result.replica().c_str());
  std::printf("camera: RMS %.3f px, %.4f mm; light planes: perspective RMS %.4f mm\n",
              report.at("camera").at("rms_px").get<double>(),
              report.at("camera").at("rms_mm").get<double>(),
              report.at("planes").at("perspective_rms_mm").get<double>());
  for (const nlohmann::json& d : report.value("dropped_views", nlohmann::json::array()))
    PrintDropped(d.at("kind").get<std::string>(), d.at("image").get<std::string>(),
                 d.at("z_mm").get<double>(), d.at("reason").get<std::string>());
}

// Input problems (a file missing or unusable) are exit 3; images that were
// read but do not give a calibration are exit 1.
ExitCode ExitCodeOf(calibration::CalibrationErrorReason reason) {
  switch (reason) {
    case calibration::CalibrationErrorReason::kUnreadableInput:
    case calibration::CalibrationErrorReason::kInvalidInput:
      return kExitInput;
    case calibration::CalibrationErrorReason::kInvalidParams:
      return kExitInternal;
    default:
      return kExitNotProcessed;
  }
}

void RunCalibrate(const CalibrateOptions& o) {
  if (!o.server.target.empty()) return RunCalibrateRemote(o);
  calibration::Manifest manifest;
  try {
    manifest = calibration::LoadManifest(o.manifest);
  } catch (const calibration::ManifestError& e) {
    throw CommandError(kExitInput, e.what());
  }
  calibration::SideCalibration result;
  try {
    result = calibration::CalibrateSide(manifest);
  } catch (const calibration::CalibrationError& e) {
    throw CommandError(ExitCodeOf(e.reason()), e.what());
  }
  // Both outputs are rendered before either is written.
  const std::string yaml = calibration::CalibrationToYaml(result, BSLS_VERSION);
  const std::string report = calibration::CalibrationReport(result).dump(1) + "\n";
  if (!o.report.empty()) WriteFileAtomically(o.report, report);
  WriteFileAtomically(o.output, yaml);
  if (o.json) {
    std::cout << calibration::CalibrationReport(result).dump() << "\n";
    return;
  }

  const auto& cr = result.camera.report;
  std::printf("%s: %s side, %d x %d px, %zu camera, %zu screen, %zu cross views\n",
              o.output.c_str(), std::string(pattern::ToString(result.side)).c_str(), result.width,
              result.height, result.camera_views.size(), result.screen_views.size(),
              result.reference_views.size());
  std::printf("camera: RMS %.3f px, %.4f mm (max %.3f px, %.4f mm) over %d points\n", cr.rms_px,
              cr.rms_mm, cr.max_px, cr.max_mm, cr.num_points);
  std::printf("light planes: perspective RMS %.4f mm (parallel %.4f mm), %d points, %d dropped\n",
              result.perspective.report.rms_mm, result.parallel.report.rms_mm,
              result.perspective.report.points_used, result.perspective.report.points_dropped);
  for (const calibration::DroppedView& d : result.dropped_views)
    PrintDropped(std::string(calibration::ToString(d.kind)), d.image.string(), d.z_mm, d.reason);
  const auto& p = result.projector;
  if (p.matrix_centre_mm) {
    std::printf(
        "projector: centre (%.1f, %.1f, %.1f) mm, distance to origin %.1f mm, axis (%.3f, %.3f, "
        "%.3f), %.1f deg from the camera axis\n",
        p.matrix_centre_mm->x(), p.matrix_centre_mm->y(), p.matrix_centre_mm->z(),
        *p.matrix_centre_distance_mm, p.optical_axis->x(), p.optical_axis->y(), p.optical_axis->z(),
        *p.camera_projector_angle_deg);
  } else {
    std::printf(
        "projector: plane-model centre (%.1f, %.1f, %.1f) mm, distance to origin %.1f mm (no "
        "cross views: no projector matrix)\n",
        p.plane_centre_mm.x(), p.plane_centre_mm.y(), p.plane_centre_mm.z(),
        p.plane_centre_distance_mm);
  }
}

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  auto opts = std::make_shared<CalibrateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "Calibrate one side (camera, light planes, projector) from a session manifest");
  cmd->add_option("manifest", opts->manifest, "Session manifest (YAML, contracts section 4)")
      ->required();
  cmd->add_option("-o,--output", opts->output, "Output calibration file (YAML)")->required();
  cmd->add_option("--report", opts->report, "Also write the figures as JSON");
  cmd->add_flag("-q,--quiet", opts->quiet, "With --server: no progress on stderr");
  cmd->add_flag("--json", opts->json,
                "Print the figures as one JSON object instead of the summary");
  AddServerOptions(*cmd, opts->server);
  cmd->callback([opts] { RunCalibrate(*opts); });
}

}  // namespace bsls::cli
