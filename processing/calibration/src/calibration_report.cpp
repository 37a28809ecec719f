#include "bsls/calibration/calibration_report.h"

namespace bsls::calibration {
namespace {

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

}  // namespace

nlohmann::json CalibrationReport(const SideCalibration& c) {
  using nlohmann::json;
  json camera_views = json::array();
  for (const auto& v : c.camera_views)
    camera_views.push_back({{"image", v.image.filename().string()},
                            {"z_mm", v.z_mm},
                            {"rms_px", v.rms_px},
                            {"rms_mm", v.rms_mm},
                            {"max_grid_residual", v.max_grid_residual}});
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
    s["matrix_rms_d"] = v.matrix_rms_d ? json(*v.matrix_rms_d) : json(nullptr);
    screens.push_back(s);
  }
  json crosses = json::array();
  for (const auto& v : c.reference_views)
    crosses.push_back({{"image", v.image.filename().string()},
                       {"z_mm", v.z_mm},
                       {"centre_px", {v.centre_px.x(), v.centre_px.y()}},
                       {"world_mm", Vec(v.world_mm)},
                       {"ray_residual_mm", v.ray_residual_mm}});
  json dropped = json::array();
  for (const auto& v : c.dropped_views)
    dropped.push_back({{"image", v.image.filename().string()},
                       {"kind", std::string(ToString(v.kind))},
                       {"index", v.index},
                       {"z_mm", v.z_mm},
                       {"reason", v.reason}});
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
              {"crosses", crosses},
              {"dropped_views", dropped},
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
  if (c.reference_ray)
    out["reference_ray"] = {{"point_mm", Vec(c.reference_ray->point_mm)},
                            {"direction", Vec(c.reference_ray->direction)}};
  return out;
}

}  // namespace bsls::calibration
