#include "bsls/simulator/calibration_session.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <system_error>

#include "bsls/common/atomic_file.h"
#include "bsls/common/errors.h"
#include "bsls/io/frame_file.h"
#include "bsls/simulator/ground_truth.h"

namespace bsls::simulator {
namespace {

// Target and screen offsets the session accepts (mm): in front of the base
// plane and well below the default projector (730 mm) and cameras (340 mm).
constexpr double kMaxZMm = 300.0;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

// Shortest text that reads back as the same double ("6.5", "4", "0.125").
std::string Number(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

bool ValidZList(const std::vector<double>& zs, const std::string& name, std::string* error) {
  std::set<double> seen;
  for (const double z : zs) {
    if (!(z >= 0.0 && z <= kMaxZMm))
      return Fail(error, "calibration session " + name + " " + Number(z) + " must lie in [0, " +
                             Number(kMaxZMm) + "] mm");
    if (!seen.insert(z).second)
      return Fail(error, "calibration session " + name + " lists " + Number(z) + " twice");
  }
  return true;
}

const char* KindPrefix(CalibrationViewKind kind) {
  switch (kind) {
    case CalibrationViewKind::kCamera:
      return "target";
    case CalibrationViewKind::kScreen:
      return "screen";
    case CalibrationViewKind::kReference:
      return "cross";
  }
  return "view";
}

// Throws when a corner of a square lands closer than `margin` px to the image
// edge (or behind the camera).
void CheckGridInImage(const geometry::PinholeModel& camera, const CalibrationSessionParams& params,
                      pattern::Side side, double z_mm) {
  const CalibrationTargetParams& target = params.target;
  const double half = target.square_mm / 2.0;
  const double margin = params.grid_margin_px;
  const int width = params.rig.width;
  const int height = params.rig.height;
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      const Eigen::Vector3d centre = TargetSquareCentre(target, r, c, z_mm);
      for (const double dx : {-half, half}) {
        for (const double dy : {-half, half}) {
          const auto image = camera.Project(centre + Eigen::Vector3d(dx, dy, 0.0));
          const bool inside = image && image->x() >= -0.5 + margin && image->y() >= -0.5 + margin &&
                              image->x() <= width - 0.5 - margin &&
                              image->y() <= height - 0.5 - margin;
          if (inside) continue;
          std::string where = "behind the camera";
          if (image)
            where = "at (" + Number(std::round(image->x() * 10) / 10) + ", " +
                    Number(std::round(image->y() * 10) / 10) + ") px";
          throw std::invalid_argument(
              "calibration session: " + std::string(pattern::ToString(side)) +
              " camera view at z = " + Number(z_mm) + " mm: a corner of square (row " +
              std::to_string(r) + ", col " + std::to_string(c) + ") lands " + where +
              ", not inside the " + std::to_string(width) + " x " + std::to_string(height) +
              " image by " + Number(margin) + " px");
        }
      }
    }
  }
}

std::string YamlViews(const std::vector<CalibrationView>& views) {
  std::string out;
  for (const CalibrationView& view : views)
    out += "  - {image: " + view.image_name + ", z_mm: " + Number(view.z_mm) + "}\n";
  return out;
}

nlohmann::json PlainViewsJson(const std::vector<CalibrationView>& views) {
  nlohmann::json out = nlohmann::json::array();
  for (const CalibrationView& view : views)
    out.push_back({{"image", view.image_name}, {"z_mm", view.z_mm}});
  return out;
}

// The rig of the session looking at the plane z = z_mm with the given slide in
// the projector; the caller sets the albedo.
Scene HorizontalPlaneScene(pattern::Side side, double z_mm, pattern::Slide slide,
                           const CalibrationSessionParams& params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument(error);
  Scene scene;
  scene.side = side;
  scene.slide = slide;
  scene.pattern = params.pattern;
  scene.camera = MakeCamera(params.rig, side);
  scene.projector = MakeProjector(params.rig);
  scene.width = params.rig.width;
  scene.height = params.rig.height;
  scene.surfaces = {std::make_shared<PlaneSurface>(PlaneSurface::Horizontal(z_mm))};
  return scene;
}

}  // namespace

bool CalibrationTargetParams::IsValid(std::string* error) const {
  if (rows < 2 || cols < 2) return Fail(error, "calibration target needs at least 2 x 2 squares");
  if (!(pitch_mm > 0.0 && std::isfinite(pitch_mm)))
    return Fail(error, "calibration target pitch_mm must be positive and finite");
  if (!(square_mm > 0.0 && square_mm < pitch_mm))
    return Fail(error, "calibration target square_mm must lie in (0, pitch_mm)");
  if (!(ground_albedo > 0.0 && ground_albedo <= 1.0))
    return Fail(error, "calibration target ground_albedo must lie in (0, 1]");
  if (!(square_albedo >= 0.0 && square_albedo < ground_albedo))
    return Fail(error, "calibration target square_albedo must lie in [0, ground_albedo)");
  if (!(edge_mm >= 0.0 && edge_mm <= square_mm / 2.0))
    return Fail(error, "calibration target edge_mm must lie in [0, square_mm / 2]");
  if (!(ground_variation >= 0.0 && ground_variation < 1.0))
    return Fail(error, "calibration target ground_variation must lie in [0, 1)");
  return true;
}

bool CalibrationSessionParams::IsValid(std::string* error) const {
  std::string why;
  if (!rig.IsValid(&why)) return Fail(error, "calibration session " + why);
  if (!pattern.IsValid(&why)) return Fail(error, "calibration session pattern: " + why);
  if (!target.IsValid(&why)) return Fail(error, why);
  if (!render.IsValid(&why)) return Fail(error, "calibration session " + why);
  if (!ValidZList(camera_z_mm, "camera_z_mm", error)) return false;
  if (!ValidZList(screen_z_mm, "screen_z_mm", error)) return false;
  if (!ValidZList(reference_z_mm, "reference_z_mm", error)) return false;
  if (camera_z_mm.empty()) return Fail(error, "calibration session needs camera views");
  if (!(target_irradiance > 0.0 && std::isfinite(target_irradiance)))
    return Fail(error, "calibration session target_irradiance must be positive and finite");
  if (!(screen_albedo > 0.0 && screen_albedo <= 1.0))
    return Fail(error, "calibration session screen_albedo must lie in (0, 1]");
  if (!std::isfinite(grid_margin_px))
    return Fail(error, "calibration session grid_margin_px must be finite");
  if (target_origin_rig_mm && !target_origin_rig_mm->allFinite())
    return Fail(error, "calibration session target_origin_rig_mm must be finite");
  return true;
}

Eigen::Vector3d TargetSquareCentre(const CalibrationTargetParams& target, int row, int col,
                                   double z_mm) {
  return {col * target.pitch_mm, -row * target.pitch_mm, z_mm};
}

Eigen::Vector3d TargetOriginInRig(const CalibrationSessionParams& params) {
  if (params.target_origin_rig_mm)
    return {params.target_origin_rig_mm->x(), params.target_origin_rig_mm->y(), 0.0};
  const CalibrationTargetParams& t = params.target;
  return {-0.5 * (t.cols - 1) * t.pitch_mm, 0.5 * (t.rows - 1) * t.pitch_mm, 0.0};
}

Eigen::Vector3d RigToCalibrationWorld(const CalibrationSessionParams& params,
                                      const Eigen::Vector3d& rig_mm) {
  return rig_mm - TargetOriginInRig(params);
}

Eigen::Vector3d CalibrationWorldToRig(const CalibrationSessionParams& params,
                                      const Eigen::Vector3d& world_mm) {
  return world_mm + TargetOriginInRig(params);
}

geometry::PinholeModel RigModelToCalibrationWorld(const CalibrationSessionParams& params,
                                                  const geometry::PinholeModel& rig_model) {
  // X_dev = R X_rig + t = R (X_world + o) + t.
  geometry::Pose pose = rig_model.pose();
  pose.translation += pose.rotation * TargetOriginInRig(params);
  return geometry::PinholeModel(rig_model.intrinsics(), pose);
}

geometry::PinholeModel CalibrationCamera(const CalibrationSessionParams& params,
                                         pattern::Side side) {
  return RigModelToCalibrationWorld(params, MakeCamera(params.rig, side));
}

geometry::PinholeModel CalibrationProjector(const CalibrationSessionParams& params) {
  return RigModelToCalibrationWorld(params, MakeProjector(params.rig));
}

AlbedoParams TargetAlbedo(const CalibrationTargetParams& target,
                          const Eigen::Vector2d& origin_rig_mm) {
  std::string error;
  if (!target.IsValid(&error)) throw std::invalid_argument(error);
  if (!origin_rig_mm.allFinite())
    throw std::invalid_argument("TargetAlbedo: the target origin must be finite");
  AlbedoParams albedo;
  albedo.base = target.ground_albedo;
  albedo.variation = target.ground_variation;
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      AlbedoPatch square;
      const Eigen::Vector3d centre = TargetSquareCentre(target, r, c, 0.0);
      square.centre_xy_mm = centre.head<2>() + origin_rig_mm;
      square.semi_axis_x_mm = square.semi_axis_y_mm = target.square_mm / 2.0;
      square.rotation_deg = 0.0;
      square.albedo = target.square_albedo;
      square.edge_mm = target.edge_mm;
      square.shape = PatchShape::kRectangle;
      albedo.patches.push_back(square);
    }
  }
  return albedo;
}

Scene CalibrationTargetScene(pattern::Side side, double z_mm,
                             const CalibrationSessionParams& params) {
  // The slide stays dark: TargetRenderParams turns the projector off.
  Scene scene = HorizontalPlaneScene(side, z_mm, pattern::BrickSlideFor(side), params);
  scene.albedo = AlbedoField(TargetAlbedo(params.target, TargetOriginInRig(params).head<2>()));
  return scene;
}

RenderParams TargetRenderParams(const CalibrationSessionParams& params) {
  RenderParams render = params.render;
  render.projector_power = 0.0;
  render.ambient = params.target_irradiance;
  return render;
}

Scene CalibrationScreenScene(pattern::Side side, double z_mm, bool cross,
                             const CalibrationSessionParams& params) {
  Scene scene = HorizontalPlaneScene(
      side, z_mm, cross ? pattern::Slide::kReferenceCross : pattern::BrickSlideFor(side), params);
  AlbedoParams albedo;
  albedo.base = params.screen_albedo;
  albedo.variation = 0.0;
  scene.albedo = AlbedoField(albedo);
  return scene;
}

std::vector<Eigen::Vector2d> TrueSquareCentres(const geometry::PinholeModel& camera,
                                               const CalibrationTargetParams& target, double z_mm) {
  std::vector<Eigen::Vector2d> centres;
  centres.reserve(static_cast<size_t>(target.rows) * target.cols);
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      const auto image = camera.Project(TargetSquareCentre(target, r, c, z_mm));
      if (!image)
        throw std::invalid_argument("TrueSquareCentres: square (" + std::to_string(r) + ", " +
                                    std::to_string(c) + ") at z = " + Number(z_mm) +
                                    " mm is not in front of the camera");
      centres.push_back(*image);
    }
  }
  return centres;
}

std::string CalibrationViewName(CalibrationViewKind kind, double z_mm) {
  std::string z;
  if (z_mm == std::floor(z_mm) && z_mm >= 0.0 && z_mm < 1000.0) {
    char buffer[8];
    std::snprintf(buffer, sizeof(buffer), "%03d", static_cast<int>(z_mm));
    z = buffer;
  } else {
    z = Number(z_mm);
    for (char& ch : z)
      if (ch == '.') ch = 'p';
  }
  return std::string(KindPrefix(kind)) + "_z" + z + ".png";
}

CalibrationSession SimulateCalibrationSession(pattern::Side side,
                                              const CalibrationSessionParams& params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument(error);
  CalibrationSession session;
  session.side = side;
  session.params = params;
  session.camera = CalibrationCamera(params, side);
  session.projector = CalibrationProjector(params);

  // Fail before spending time on rendering.
  if (params.grid_margin_px >= 0.0)
    for (const double z : params.camera_z_mm) CheckGridInImage(session.camera, params, side, z);

  std::uint32_t seed = params.render.seed;
  const RenderParams target_render = TargetRenderParams(params);
  for (const double z : params.camera_z_mm) {
    CalibrationView view;
    view.kind = CalibrationViewKind::kCamera;
    view.z_mm = z;
    view.image_name = CalibrationViewName(view.kind, z);
    view.image =
        Renderer(CalibrationTargetScene(side, z, params), target_render).RenderImage(seed++);
    view.square_centres = TrueSquareCentres(session.camera, params.target, z);
    session.camera_views.push_back(std::move(view));
  }
  for (const bool cross : {false, true}) {
    const auto& zs = cross ? params.reference_z_mm : params.screen_z_mm;
    auto& views = cross ? session.reference_views : session.screen_views;
    for (const double z : zs) {
      CalibrationView view;
      view.kind = cross ? CalibrationViewKind::kReference : CalibrationViewKind::kScreen;
      view.z_mm = z;
      view.image_name = CalibrationViewName(view.kind, z);
      view.image = Renderer(CalibrationScreenScene(side, z, cross, params), params.render)
                       .RenderImage(seed++);
      views.push_back(std::move(view));
    }
  }
  return session;
}

std::string ManifestYaml(const CalibrationSession& session) {
  const CalibrationSessionParams& params = session.params;
  std::string out;
  out += "# BSLS calibration session (contracts section 4), simulated by bsls::simulator.\n";
  out += "side: " + std::string(pattern::ToString(session.side)) + "\n";
  out += "target: {rows: " + std::to_string(params.target.rows) +
         ", cols: " + std::to_string(params.target.cols) +
         ", pitch_mm: " + Number(params.target.pitch_mm) +
         ", square_mm: " + Number(params.target.square_mm) + "}\n";
  out += session.camera_views.empty() ? "camera_views: []\n" : "camera_views:\n";
  out += YamlViews(session.camera_views);
  out += session.screen_views.empty() ? "screen_views: []\n" : "screen_views:\n";
  out += YamlViews(session.screen_views);
  if (!session.reference_views.empty()) {
    out += "reference_views:\n";
    out += YamlViews(session.reference_views);
  }
  out += "pattern: {lines: " + std::to_string(params.pattern.lines) +
         ", rows: " + std::to_string(params.pattern.rows) + "}\n";
  return out;
}

nlohmann::json TruthJson(const CalibrationSession& session) {
  const CalibrationSessionParams& params = session.params;
  nlohmann::json camera_views = nlohmann::json::array();
  for (const CalibrationView& view : session.camera_views) {
    nlohmann::json squares = nlohmann::json::array();
    for (int r = 0; r < params.target.rows; ++r) {
      for (int c = 0; c < params.target.cols; ++c) {
        const Eigen::Vector2d& image = view.square_centres[r * params.target.cols + c];
        const Eigen::Vector3d world = TargetSquareCentre(params.target, r, c, view.z_mm);
        squares.push_back({{"row", r},
                           {"col", c},
                           {"x", image.x()},
                           {"y", image.y()},
                           {"world", {world.x(), world.y(), world.z()}}});
      }
    }
    camera_views.push_back({{"image", view.image_name}, {"z_mm", view.z_mm}, {"squares", squares}});
  }
  return {
      {"side", std::string(pattern::ToString(session.side))},
      {"width", params.rig.width},
      {"height", params.rig.height},
      {"target",
       {{"rows", params.target.rows},
        {"cols", params.target.cols},
        {"pitch_mm", params.target.pitch_mm},
        {"square_mm", params.target.square_mm}}},
      {"pattern",
       {{"lines", params.pattern.lines},
        {"rows", params.pattern.rows},
        {"stroke_width", params.pattern.stroke_width}}},
      {"target_origin_rig_mm", {TargetOriginInRig(params).x(), TargetOriginInRig(params).y(), 0.0}},
      {"camera", DeviceJson(session.camera)},
      {"projector", DeviceJson(session.projector)},
      {"camera_views", camera_views},
      {"screen_views", PlainViewsJson(session.screen_views)},
      {"reference_views", PlainViewsJson(session.reference_views)}};
}

std::filesystem::path WriteCalibrationSession(const CalibrationSession& session,
                                              const std::filesystem::path& folder) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw OutputError(folder.string() + ": cannot create the folder: " + ec.message());
  for (const auto* views : {&session.camera_views, &session.screen_views, &session.reference_views})
    for (const CalibrationView& view : *views)
      io::WritePngAtomically((folder / view.image_name).string(), view.image);
  WriteFileAtomically((folder / kSessionTruthName).string(), TruthJson(session).dump(1) + "\n");
  const std::filesystem::path manifest = folder / kSessionManifestName;
  WriteFileAtomically(manifest.string(), ManifestYaml(session));
  return manifest;
}

}  // namespace bsls::simulator
