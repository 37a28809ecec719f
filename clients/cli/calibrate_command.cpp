// bsls calibrate: calibrate one side (camera, light planes, projector) from a
// session manifest (contracts section 4) and write its calibration file.
#include <array>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "bsls/calibration/manifest.h"
#include "bsls/common/atomic_file.h"
#include "command.h"
#include "daemon_connection.h"
#include "processing_route.h"

namespace bsls::cli {
namespace {

struct CalibrateOptions {
  std::string manifest;
  std::string output;
  std::string report;
  bool quiet = false;
  bool json = false;      // the report on stdout instead of the summary
  ServiceAddress server;  // target empty: calibrated in this process
};

// One summary line for a view the calibration left out.
void PrintDropped(const std::string& kind, const std::string& image, double z_mm,
                  const std::string& reason) {
  std::printf("dropped %s view %s (z = %g mm): %s\n", kind.c_str(), image.c_str(), z_mm,
              reason.c_str());
}

// The session's manifest and every image it names (inside the manifest's
// folder, by path relative to it), as uploaded to the service.
std::vector<processing::UploadFile> SessionFiles(const std::string& manifest_path) {
  namespace fs = std::filesystem;
  calibration::Manifest manifest;
  try {
    manifest = calibration::LoadManifest(manifest_path);  // checks it and that every image exists
  } catch (const calibration::ManifestError& e) {
    throw CommandError(kExitInput, e.what());
  }
  const fs::path folder = fs::weakly_canonical(fs::path(manifest_path).parent_path().empty()
                                                   ? fs::path(".")
                                                   : fs::path(manifest_path).parent_path());
  std::vector<processing::UploadFile> files;
  std::set<std::string> named;  // an image may serve more than one view: sent once
  for (const auto* views :
       {&manifest.camera_views, &manifest.screen_views, &manifest.reference_views})
    for (const calibration::ManifestView& view : *views) {
      const fs::path image = fs::weakly_canonical(view.image);
      const fs::path relative = image.lexically_relative(folder);
      if (relative.empty() || *relative.begin() == "..")
        throw CommandError(kExitInput, manifest_path + ": image " + view.image.string() +
                                           " is outside the manifest's folder: a session is "
                                           "the manifest's folder and what is inside it");
      if (named.insert(relative.generic_string()).second)
        files.push_back({relative.generic_string(), ReadInputFile(image.string(), "image")});
    }
  return files;
}

// The summary on stdout, from the calibration report (CalibrationReport).
void PrintCalibrationSummary(const std::string& output, const nlohmann::json& report,
                             const v1::Result& result) {
  const nlohmann::json& camera = report.at("camera");
  const nlohmann::json& planes = report.at("planes");
  std::printf("%s: %s side, %d x %d px, %zu camera, %zu screen, %zu cross views, id %s\n",
              output.c_str(), report.at("side").get<std::string>().c_str(),
              report.at("width").get<int>(), report.at("height").get<int>(),
              camera.at("views").size(), report.at("screens").size(), report.at("crosses").size(),
              result.calibration_id().c_str());
  std::printf("camera: RMS %.3f px, %.4f mm (max %.3f px, %.4f mm) over %d points\n",
              camera.at("rms_px").get<double>(), camera.at("rms_mm").get<double>(),
              camera.at("max_px").get<double>(), camera.at("max_mm").get<double>(),
              camera.at("points").get<int>());
  std::printf("light planes: perspective RMS %.4f mm (parallel %.4f mm), %d points, %d dropped\n",
              planes.at("perspective_rms_mm").get<double>(),
              planes.at("parallel_rms_mm").get<double>(), planes.at("points_used").get<int>(),
              planes.at("points_dropped").get<int>());
  for (const nlohmann::json& d : report.value("dropped_views", nlohmann::json::array()))
    PrintDropped(d.at("kind").get<std::string>(), d.at("image").get<std::string>(),
                 d.at("z_mm").get<double>(), d.at("reason").get<std::string>());
  const nlohmann::json& p = report.at("projector");
  auto vec = [](const nlohmann::json& v) {
    return std::array<double, 3>{v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
  };
  if (p.contains("matrix_centre_mm")) {
    const auto c = vec(p.at("matrix_centre_mm"));
    const auto a = vec(p.at("optical_axis"));
    std::printf(
        "projector: centre (%.1f, %.1f, %.1f) mm, distance to origin %.1f mm, axis (%.3f, %.3f, "
        "%.3f), %.1f deg from the camera axis\n",
        c[0], c[1], c[2], p.at("matrix_centre_distance_mm").get<double>(), a[0], a[1], a[2],
        p.at("camera_projector_angle_deg").get<double>());
  } else {
    const auto c = vec(p.at("plane_centre_mm"));
    std::printf(
        "projector: plane-model centre (%.1f, %.1f, %.1f) mm, distance to origin %.1f mm (no "
        "cross views: no projector matrix)\n",
        c[0], c[1], c[2], p.at("plane_centre_distance_mm").get<double>());
  }
}

void RunCalibrate(const CalibrateOptions& o) {
  const std::vector<processing::UploadFile> files = SessionFiles(o.manifest);
  ProcessingRoute route(o.server);
  const processing::WorkOutcome out =
      route.client().Calibrate(ReadInputFile(o.manifest, "manifest"), files,
                               o.manifest.substr(0, 256), route.Progress(o.quiet || o.json));
  route.Check(out.status, o.manifest);
  const std::string& report_text = out.files.at("calibration-report.json");
  const nlohmann::json report = nlohmann::json::parse(report_text);
  if (!o.report.empty()) WriteFileAtomically(o.report, report_text);
  WriteFileAtomically(o.output, out.files.at("calibration.yaml"));
  if (o.json) {
    nlohmann::json summary = report;
    summary["calibration_id"] = out.result.calibration_id();
    summary["replica"] = out.result.replica();
    std::cout << summary.dump() << "\n";
    return;
  }
  PrintCalibrationSummary(o.output, report, out.result);
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
  cmd->add_flag("-q,--quiet", opts->quiet, "No progress on stderr");
  cmd->add_flag("--json", opts->json,
                "Print the figures as one JSON object instead of the summary");
  AddServerOptions(*cmd, opts->server);
  cmd->callback([opts] { RunCalibrate(*opts); });
}

}  // namespace bsls::cli
