// A simulated calibration session for one side (thesis chapter 6): the same
// rig (camera, projector) as ThesisScene for that side, and
//   camera views     the target of contracts section 3 (rows x cols dark
//                    squares on white) at each z of a list, lit uniformly
//                    (ambient light only, projector dark), for the camera
//                    calibration (thesis 6.1, 6.3: "8x8 squares ... moved in a
//                    direction perpendicular to the plane of the target");
//   screen views     a blank white plane at z with the side's brick slide
//                    projected, for the projector calibration (thesis 6.2);
//   reference views  the same plane with slide 1 (the cross).
// Written as 8-bit grey PNGs, the session manifest of contracts section 4 and
// a truth JSON (true camera, projector and square centres).
//
// Frames and units: millimetres. Two frames differ by a translation in x, y:
//   rig frame          the frame of RigParams / ThesisScene (projector above
//                      the rig origin, cameras mirrored in x = 0);
//   calibration world  contracts section 3: origin at the centre of target
//                      square (0, 0) at z = 0, x along increasing column, y
//                      up (decreasing row); square (r, c) of the view at
//                      offset z is at (c * pitch, -r * pitch, z).
// Square (0, 0) lies at rig (x, y) = TargetOriginInRig(params), so a rig point
// X is the world point X - (origin_x, origin_y, 0) (RigToCalibrationWorld).
// The session's camera and projector and its truth JSON are given in the
// calibration world frame, which is what a calibration recovers. Image pixels
// with the origin at the centre of the top-left pixel. The projector's image
// is the slide in line pitches d (scene.h).
//
// Placement (default rig and target): the grid is centred on the rig's x = y
// = 0, between the two cameras' views, so one set of target positions serves
// both sides (one shared world frame) and the grid lies near the middle of
// both images. With the contract's literal placement (square (0, 0) at the rig
// origin, target_origin_rig_mm = (0, 0)) the thesis 8 x 8 target covers only
// the lower-right 85 x 110 px of the 512 x 512 images and the left camera
// loses it above z = 105 mm; camera distortion fitted on such a patch
// extrapolates badly over the face (docs/calibration.md).
//
// Errors: std::invalid_argument naming the field for invalid params, and
// naming the view and the square when a camera view does not show the whole
// grid (CalibrationSessionParams::grid_margin_px); bsls::OutputError from
// WriteCalibrationSession.
//
// Thread-safety: pure functions of their arguments; rendering runs rows in
// parallel (Renderer).
#ifndef BSLS_SIMULATOR_CALIBRATION_SESSION_H_
#define BSLS_SIMULATOR_CALIBRATION_SESSION_H_

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bsls/geometry/pinhole_model.h"
#include "bsls/pattern/brick_pattern.h"
#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace bsls::simulator {

// The printed calibration target (contracts section 3; thesis 6.3: 8 x 8
// squares, 6.5 mm apart).
struct CalibrationTargetParams {
  int rows = 8;                 // squares per column, >= 2
  int cols = 8;                 // squares per row, >= 2
  double pitch_mm = 6.5;        // centre-to-centre, > 0
  double square_mm = 4.0;       // side, in (0, pitch_mm)
  double ground_albedo = 0.85;  // the white paper, (0, 1]
  double square_albedo = 0.05;  // the printed squares, [0, ground_albedo)
  // Width (mm) of a soft printed edge (smoothstep across the outline), in
  // [0, square_mm / 2]. 0.5 mm is about 1 px in the default image: it stands
  // for toner spread and defocus, and keeps the renderer's n x n ray grid
  // from quantising a sharp edge (with n = 3 a sharp edge moves in 1/3 px
  // steps, which shifts square centres by up to 0.2 px).
  double edge_mm = 0.5;
  // Smooth variation of the ground (paper and light not quite uniform), as
  // AlbedoParams::variation; the squares stay at square_albedo.
  double ground_variation = 0.03;

  // True when the numbers describe a target; otherwise names the field.
  bool IsValid(std::string* error) const;
};

// Everything a session is rendered from. The rig, pattern and render
// settings are those of ThesisScene / Render for the same side.
struct CalibrationSessionParams {
  RigParams rig;  // image size is rig.width x rig.height
  pattern::PatternSpec pattern;
  CalibrationTargetParams target;
  // Rig-frame (x, y) in mm of the centre of square (0, 0): where the target
  // was laid on the rig. Unset: the grid centred on the rig's x = y = 0
  // (TargetOriginInRig). (0, 0) puts the calibration world frame on the rig
  // frame (the target then lies in the rig's x >= 0, y <= 0 quadrant).
  std::optional<Eigen::Vector2d> target_origin_rig_mm;
  // Target offsets (mm, >= 0, distinct). The thesis used 15 planes 10 .. 150
  // mm; the default is 11 planes 0 .. 100 mm, the depth of the face.
  std::vector<double> camera_z_mm = {0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100};
  // Screen (brick slide) and reference (cross) planes, mm, distinct.
  std::vector<double> screen_z_mm = {0, 30, 60, 90, 120};
  std::vector<double> reference_z_mm = {0, 30, 60, 90, 120};
  // Noise, seed, blur, supersampling, gain of every view. View k (counted
  // over camera, then screen, then reference views) is noised with seed
  // render.seed + k.
  RenderParams render;
  // Camera views: uniform irradiance on the target (RenderParams::ambient
  // units; the projector is off). 0.9 puts the paper near grey 236.
  double target_irradiance = 0.9;
  // Screen and reference views: albedo of the blank screen, (0, 1].
  double screen_albedo = 0.85;
  // Camera views: every corner of every square must land at least this far
  // (px) inside the image; otherwise SimulateCalibrationSession throws.
  // Negative: no check (views with the grid partly outside are rendered).
  double grid_margin_px = 2.0;

  // True when every part is valid; otherwise names the part and the reason.
  bool IsValid(std::string* error) const;
};

// Which set of the manifest a view belongs to.
enum class CalibrationViewKind { kCamera, kScreen, kReference };

// One rendered view.
struct CalibrationView {
  CalibrationViewKind kind = CalibrationViewKind::kCamera;
  double z_mm = 0.0;
  std::string image_name;  // file name, relative to the manifest's folder
  cv::Mat image;           // CV_8UC1, rig.height x rig.width
  // Camera views: the true image point (px) of every square centre, row-major
  // (index r * cols + c), distortion applied. Empty for other views.
  std::vector<Eigen::Vector2d> square_centres;
};

// A rendered session for one side.
struct CalibrationSession {
  pattern::Side side = pattern::Side::kLeft;
  CalibrationSessionParams params;
  // Both in the calibration world frame (CalibrationCamera, CalibrationProjector).
  geometry::PinholeModel camera;  // pixels; MakeCamera(params.rig, side) moved to the world frame
  geometry::PinholeModel projector;  // slide units d; MakeProjector(params.rig) moved likewise
  std::vector<CalibrationView> camera_views;     // in params.camera_z_mm order
  std::vector<CalibrationView> screen_views;     // in params.screen_z_mm order
  std::vector<CalibrationView> reference_views;  // in params.reference_z_mm order
};

// World point (mm, calibration world frame) of the centre of square (row,
// col) with the target at z_mm.
Eigen::Vector3d TargetSquareCentre(const CalibrationTargetParams& target, int row, int col,
                                   double z_mm);

// Rig-frame (x, y, 0) of the centre of square (0, 0): params.target_origin_rig_mm,
// or when unset the grid centred on the rig's x = y = 0:
// (-(cols - 1) / 2 * pitch, (rows - 1) / 2 * pitch, 0).
Eigen::Vector3d TargetOriginInRig(const CalibrationSessionParams& params);
// The calibration world point of a rig-frame point (mm): rig - TargetOriginInRig.
Eigen::Vector3d RigToCalibrationWorld(const CalibrationSessionParams& params,
                                      const Eigen::Vector3d& rig_mm);
// The rig-frame point of a calibration world point (mm); inverse of the above.
Eigen::Vector3d CalibrationWorldToRig(const CalibrationSessionParams& params,
                                      const Eigen::Vector3d& world_mm);
// A device model given in the rig frame, re-expressed in the calibration
// world frame (same intrinsics, same centre in space).
geometry::PinholeModel RigModelToCalibrationWorld(const CalibrationSessionParams& params,
                                                  const geometry::PinholeModel& rig_model);
// The side's camera / the projector of params.rig in the calibration world
// frame: what a calibration of the session must recover. Throw
// std::invalid_argument for invalid params.
geometry::PinholeModel CalibrationCamera(const CalibrationSessionParams& params,
                                         pattern::Side side);
geometry::PinholeModel CalibrationProjector(const CalibrationSessionParams& params);

// The albedo of the target, in the rig frame with square (0, 0) at rig
// (x, y) = origin_rig_mm: ground with its variation and one soft-edged
// rectangular patch per square (anti-aliased by the renderer's
// supersampling). Throws std::invalid_argument for invalid params.
AlbedoParams TargetAlbedo(const CalibrationTargetParams& target,
                          const Eigen::Vector2d& origin_rig_mm = Eigen::Vector2d::Zero());

// The scene (rig frame) of a camera view: the target plane at z_mm, placed
// at TargetOriginInRig, seen by the side's camera. Render it with
// TargetRenderParams. Throws std::invalid_argument.
Scene CalibrationTargetScene(pattern::Side side, double z_mm,
                             const CalibrationSessionParams& params);
// params.render with the projector off and ambient = target_irradiance.
RenderParams TargetRenderParams(const CalibrationSessionParams& params);
// The scene of a screen view (cross = false: the side's brick slide) or a
// reference view (cross = true: slide 1): a white plane at z_mm. Render it
// with params.render. Throws std::invalid_argument.
Scene CalibrationScreenScene(pattern::Side side, double z_mm, bool cross,
                             const CalibrationSessionParams& params);

// True image points (px, distorted) of every square centre at z_mm,
// row-major, for a camera given in the calibration world frame. Throws std::invalid_argument when a
// centre is not in front of the camera.
std::vector<Eigen::Vector2d> TrueSquareCentres(const geometry::PinholeModel& camera,
                                               const CalibrationTargetParams& target, double z_mm);

// "target_z010.png" style names: prefix, "_z", z in mm (three digits when
// whole, else with 'p' for the decimal point, e.g. "target_z12p5.png").
std::string CalibrationViewName(CalibrationViewKind kind, double z_mm);

// Renders every view of a session for `side`. Throws std::invalid_argument
// for invalid params, or naming the view and square when a camera view's grid
// is not inside the image by grid_margin_px.
CalibrationSession SimulateCalibrationSession(pattern::Side side,
                                              const CalibrationSessionParams& params = {});

// The manifest of contracts section 4 (YAML text, image names relative).
std::string ManifestYaml(const CalibrationSession& session);

// The truth of a session:
// {"side", "width", "height",
//  "target": {"rows", "cols", "pitch_mm", "square_mm"},
//  "pattern": {"lines", "rows", "stroke_width"},
//  "target_origin_rig_mm": [x, y, 0]  (rig-frame position of square (0, 0)),
//  "camera":    {"fx", "fy", "cx", "cy", "k1", "k2",            (pixels)
//                "rotation": [9, row-major, world->device], "translation": [3] (mm)},
//               in the calibration world frame,
//  "projector": same layout, focal length and principal point in slide pitches d,
//  "camera_views": [{"image", "z_mm",
//                    "squares": [{"row", "col", "x", "y", "world": [x, y, z]}]}],
//  "screen_views": [{"image", "z_mm"}], "reference_views": [{"image", "z_mm"}]}
// Square x, y: the exact projection of the square's centre (px), row-major.
nlohmann::json TruthJson(const CalibrationSession& session);

// File names WriteCalibrationSession uses inside its folder.
inline constexpr const char* kSessionManifestName = "session.yaml";
inline constexpr const char* kSessionTruthName = "truth.json";

// Writes every view's PNG, then truth.json, then session.yaml (last, so a
// manifest only exists once everything it lists does) into `folder`, creating
// it when needed; each file is written atomically. Returns the manifest path.
// Throws bsls::OutputError naming the file.
std::filesystem::path WriteCalibrationSession(const CalibrationSession& session,
                                              const std::filesystem::path& folder);

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_CALIBRATION_SESSION_H_
