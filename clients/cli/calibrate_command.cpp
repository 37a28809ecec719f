// bsls calibrate: calibrate one side (camera, light planes, projector) from a
// session manifest (contracts section 4) and write its calibration file.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "bsls/calibration/calibration_file.h"
#include "bsls/calibration/manifest.h"
#include "bsls/calibration/side_calibration.h"
#include "bsls/io/frame_file.h"
#include "command.h"

namespace bsls::cli {
namespace {

struct CalibrateOptions {
  std::string manifest;
  std::string output;
  std::string report;
};

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

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// The layout of the simulator's truth.json devices: intrinsics, row-major
// world -> device rotation, translation (mm).
nlohmann::json DeviceJson(const geometry::PinholeModel& model) {
  const geometry::Intrinsics& in = model.intrinsics();
  nlohmann::json rotation = nlohmann::json::array();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rotation.push_back(model.pose().rotation(i, j));
  return {{"fx", in.fx},          {"fy", in.fy},
          {"cx", in.cx},          {"cy", in.cy},
          {"k1", in.k1},          {"k2", in.k2},
          {"rotation", rotation}, {"translation", Vec(model.pose().translation)}};
}

nlohmann::json ReportJson(const calibration::SideCalibration& c) {
  using nlohmann::json;
  json camera_views = json::array();
  for (const auto& v : c.camera_views)
    camera_views.push_back({{"image", v.image.filename().string()},
                            {"z_mm", v.z_mm},
                            {"rms_px", v.rms_px},
                            {"rms_mm", v.rms_mm}});
  json screens = json::array();
  for (const auto& v : c.screen_views) {
    json s = {{"image", v.image.filename().string()},
              {"z_mm", v.z_mm},
              {"lines", v.lines},
              {"stripe_points", v.stripe_points},
              {"junctions", v.junctions},
              {"plane_rms_mm", v.plane_rms_mm},
              {"matrix_junctions", v.matrix_junctions}};
    s["q_offset"] = v.q_offset ? json(*v.q_offset) : json(nullptr);
    screens.push_back(s);
  }
  const auto& cr = c.camera.report;
  json out = {{"side", std::string(pattern::ToString(c.side))},
              {"width", c.width},
              {"height", c.height},
              {"manifest_sha256", c.manifest_sha256},
              {"camera",
               {{"rms_px", cr.rms_px},
                {"max_px", cr.max_px},
                {"rms_mm", cr.rms_mm},
                {"max_mm", cr.max_mm},
                {"points", cr.num_points},
                {"centre_mm", Vec(c.camera.model.Centre())},
                {"model", DeviceJson(c.camera.model)},
                {"views", camera_views}}},
              {"planes",
               {{"perspective_rms_mm", c.perspective.report.rms_mm},
                {"perspective_max_mm", c.perspective.report.max_mm},
                {"parallel_rms_mm", c.parallel.report.rms_mm},
                {"points_used", c.perspective.report.points_used},
                {"points_dropped", c.perspective.report.points_dropped}}},
              {"projector",
               {{"plane_centre_mm", Vec(c.projector.plane_centre_mm)},
                {"plane_axis", Vec(c.projector.plane_axis)},
                {"plane_centre_distance_mm", c.projector.plane_centre_distance_mm}}},
              {"screens", screens},
              {"uncertainty",
               {{"stripe_centre_px", c.sigmas.stripe_centre_px},
                {"target_point_px", c.sigmas.target_point_px},
                {"plane_mm", c.sigmas.plane_mm}}},
              {"times_ms",
               {{"camera", c.diagnostics.times.camera_ms},
                {"stripes", c.diagnostics.times.stripes_ms},
                {"planes", c.diagnostics.times.planes_ms},
                {"reference", c.diagnostics.times.reference_ms},
                {"total", c.diagnostics.times.total_ms}}}};
  if (c.projector_matrix) {
    json& p = out["projector"];
    p["matrix_centre_mm"] = Vec(*c.projector.matrix_centre_mm);
    p["optical_axis"] = Vec(*c.projector.optical_axis);
    p["matrix_centre_distance_mm"] = *c.projector.matrix_centre_distance_mm;
    p["camera_projector_angle_deg"] = *c.projector.camera_projector_angle_deg;
    p["matrix_rms_d"] = c.projector_matrix->report.rms_d;
    p["model"] = DeviceJson(c.projector_matrix->model);
    p["matrix_junctions"] = c.projector_matrix->report.points_used;
  }
  return out;
}

void RunCalibrate(const CalibrateOptions& o) {
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
  const std::string report = ReportJson(result).dump(1) + "\n";
  if (!o.report.empty()) io::WriteFileAtomically(o.report, report);
  io::WriteFileAtomically(o.output, yaml);

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
  cmd->callback([opts] { RunCalibrate(*opts); });
}

}  // namespace bsls::cli
