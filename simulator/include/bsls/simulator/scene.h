// A simulated BSLS set-up: surfaces, their albedo, one camera, the projector
// and the slide in it; and the thesis set-up as the default scene factory
// (thesis 2.6, Tables 2.1 and 2.2; test objects of thesis 7.1).
//
// Frames and units (contracts section 3, bsls/geometry/pinhole_model.h):
//   world      millimetres; x right, y up, z towards cameras and projector;
//              the base plane is z = 0.
//   camera     PinholeModel in pixels, origin at the centre of the top-left
//              pixel; pixel (i, j) covers [i-0.5, i+0.5] x [j-0.5, j+0.5].
//   projector  PinholeModel whose image is the slide plane (s, t) in line
//              pitches d, principal point (0, 0); s towards world +x, t towards
//              world -y when it looks straight down.
//
// Errors: factories throw MeshLoadError (mesh.h) when a bundled mesh file is
// missing or corrupt (the message names the file and the reason), and
// std::invalid_argument naming the field when options are out of range.
//
// Thread-safety: a Scene is a value; its const members may be called
// concurrently. Surfaces are immutable and shared between copies.
#ifndef BSLS_SIMULATOR_SCENE_H_
#define BSLS_SIMULATOR_SCENE_H_

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bsls/geometry/pinhole_model.h"
#include "bsls/pattern/brick_pattern.h"
#include "bsls/simulator/albedo.h"
#include "bsls/simulator/lesion.h"
#include "bsls/simulator/mesh.h"
#include "bsls/simulator/surface.h"

namespace bsls::simulator {

// A point is in the projector's shadow when something lies more than this (mm)
// in front of it along the projector ray.
inline constexpr double kShadowToleranceMm = 1e-3;

// What the camera sees along one ray.
struct SurfaceSample {
  Hit hit;           // normals flipped to the camera's side of the surface
  bool lit = false;  // the projector lights the side the camera sees, unblocked
  Eigen::Vector2d slide_st = Eigen::Vector2d::Zero();  // slide point lighting it (d), when lit
  double cos_incidence = 0.0;          // shading normal . direction to the projector (may be < 0)
  double projector_distance_mm = 0.0;  // from the projector centre
  double projector_depth_mm = 0.0;     // along the projector's optical axis
};

// Everything needed to render one side's image.
struct Scene {
  // Hit in order; the nearest hit over all wins. Shared: surfaces are immutable
  // and reused by copies of a scene (left/right, perturbed cameras).
  std::vector<std::shared_ptr<const Surface>> surfaces;
  AlbedoField albedo;
  geometry::PinholeModel camera;  // pixels
  int width = 512;                // image size, pixels
  int height = 512;
  geometry::PinholeModel projector;           // slide units d
  pattern::Side side = pattern::Side::kLeft;  // labels u = UFromS(side, s)
  pattern::Slide slide = pattern::Slide::kLeftBrick;
  pattern::PatternSpec pattern;

  // True when the scene can be rendered; otherwise says which part and why.
  bool IsValid(std::string* error) const;
  // Nearest hit over all surfaces with distance below max_distance (mm).
  std::optional<Hit> Intersect(const geometry::Ray& ray, double max_distance) const;
  // True when nothing lies between the projector centre and `point` (mm).
  bool ProjectorReaches(const Eigen::Vector3d& point) const;
  // The surface seen along `camera_ray` (from the camera centre) and how the
  // projector lights it; nullopt when the ray hits nothing.
  std::optional<SurfaceSample> TraceCameraRay(const geometry::Ray& camera_ray) const;
};

// The objects of the thesis test scenes.
enum class SurfaceKind { kPlane, kRamp, kBall, kFace, kBunny };

// Returns "plane", "ramp", "ball", "face" or "bunny".
std::string_view ToString(SurfaceKind kind);
// Parses the names of ToString; nullopt for anything else.
std::optional<SurfaceKind> ParseSurfaceKind(std::string_view text);

// The face model's file in a data directory (DefaultDataDir()).
inline constexpr const char* kFaceFileName = "canonical_face_model.obj";

// Where the bundled meshes are: $BSLS_DATA_DIR when set and non-empty, else
// the installed data directory when it holds kFaceFileName, else the
// source tree's simulator/data.
std::filesystem::path DefaultDataDir();

// Camera and projector placement. Defaults: thesis Tables 2.1 and 2.2.
struct RigParams {
  // Projector (thesis: dp = 730 mm, fp = 90 mm, slide pitch dg = 0.8 mm).
  Eigen::Vector3d projector_centre_mm{0.0, 0.0, 730.0};
  Eigen::Vector3d projector_target_mm{0.0, 0.0, 0.0};
  // Focal length in slide pitches: a 90 mm lens focused at 730 mm sits
  // 102.7 mm from the slide, / 0.8 mm = 128 d; projected pitch 5.7 mm at z = 0.
  double projector_focal_d = 128.0;
  double projector_k1 = 0.0;  // radial distortion, normalised coordinates

  // Camera of the LEFT side; the right camera is its mirror image in x = 0
  // (thesis: dc = 340 mm, dcp = 240 mm).
  Eigen::Vector3d left_camera_centre_mm{-240.0, 0.0, 340.0};
  Eigen::Vector3d left_camera_target_mm{-35.0, 0.0, 50.0};
  // Focal length in units of the image height: 1.76 x 512 = 901 px makes the
  // bundled face (177 mm tall) fill about 87 % of the image height.
  double camera_focal_per_height = 1.76;
  double camera_k1 = -0.05;  // mild barrel distortion, normalised coordinates
  double camera_k2 = 0.0;
  int width = 512;  // pixels; principal point at the image centre
  int height = 512;

  // True when the numbers describe a usable rig; otherwise names the field.
  bool IsValid(std::string* error) const;
};

// The projector of a rig, looking from its centre at its target with slide t
// pointing along world -y. Throws std::invalid_argument for an invalid rig.
geometry::PinholeModel MakeProjector(const RigParams& rig);
// The camera of a side (right = mirror of left in x = 0), image up along
// world +y. Throws std::invalid_argument for an invalid rig.
geometry::PinholeModel MakeCamera(const RigParams& rig, pattern::Side side);

// The bundled face mask in millimetres: the OBJ (cm) scaled by 10, Loop
// subdivided, then placed with the nose tip (vertex of largest z) at x = 0,
// the back (smallest z) at z = 0 and the vertical extent centred on y = 0.
struct FaceModelParams {
  std::filesystem::path obj_path;  // empty: DefaultDataDir() / canonical_face_model.obj
  int subdivision_levels = 2;      // Loop subdivision rounds, 0..4 (898 x 4^levels triangles)
  double mm_per_unit = 10.0;       // the OBJ is in centimetres

  // True when the numbers are in range; otherwise names the field.
  bool IsValid(std::string* error) const;
};
// Loads and places the face. Throws MeshLoadError naming the file and reason.
IndexedMesh LoadFaceMesh(const FaceModelParams& params);
// The face's two eyebrow patches (albedo 0.3, soft edges), in the frame of LoadFaceMesh.
std::vector<AlbedoPatch> FaceEyebrowPatches();

// The Stanford bunny standing on the base plane: file y (up) -> world z,
// file z -> world -y, scaled, lowest point at z = 0, bounding-box centre at
// centre_xy_mm.
struct BunnyParams {
  std::filesystem::path json_path;           // empty: DefaultDataDir() / stanford_bunny.json
  double mm_per_unit = 12.0;                 // about 120 mm wide and tall
  Eigen::Vector2d centre_xy_mm{-40.0, 0.0};  // left side; mirrored for the right
  int subdivision_levels = 0;                // Loop subdivision rounds, 0..3

  // True when the numbers are in range; otherwise names the field.
  bool IsValid(std::string* error) const;
};
// Loads and places the bunny for a side. Throws MeshLoadError naming the file.
IndexedMesh LoadBunnyMesh(const BunnyParams& params, pattern::Side side);

// Options of ThesisScene. Object placements are given for the LEFT side and
// mirrored in x = 0 for the right side.
struct ThesisSceneOptions {
  RigParams rig;
  pattern::PatternSpec pattern;
  bool reference_cross = false;  // project slide 1 instead of the side's brick slide
  FaceModelParams face;
  bool face_eyebrows = true;        // add FaceEyebrowPatches() to the albedo
  bool face_on_base_plane = false;  // face scenes: also the base plane (else black background)
  // Lumps and cavities pressed into the face (thesis 7.2, Tables 7.3-7.4).
  // World (x, y): not mirrored for the right side, both sides see one face.
  std::vector<LesionParams> face_lesions;
  // Rises towards +x (towards the left camera, 12 deg off its view axis) from
  // x = -120 to +30 mm, 150 mm high: the whole lit half and line 0 stay visible.
  RampParams ramp;
  // A 20 mm high cap of a 130 mm ball rising from the base plane (rim slope
  // 32 deg): its surface joins the plane along the rim, so every line can be
  // followed onto it, and even its far side (facing away from the camera)
  // keeps the lines 5 px or more apart. A steeper ball hides whole lines from
  // the camera behind its rim, which no decoder can label without a
  // calibration (docs/decoding.md).
  BallParams ball{.centre_mm = {-75.0, 0.0, -110.0}, .radius_mm = 130.0};
  BunnyParams bunny;
  // Smooth +-10 % variation around 0.8; patches here apply to every scene kind.
  AlbedoParams albedo;

  // True when every part is valid; otherwise names the part and the reason.
  bool IsValid(std::string* error) const;
};

// The thesis set-up for one side and one object. Plane: the base plane only.
// Ramp, ball, bunny: the object plus the base plane. Face: the face mask
// (plus the base plane when asked), with its lesions. Throws MeshLoadError for
// face/bunny files and std::invalid_argument for invalid options (a lesion
// that is invalid or overlaps another).
Scene ThesisScene(pattern::Side side, SurfaceKind kind, const ThesisSceneOptions& options = {});

}  // namespace bsls::simulator

#endif  // BSLS_SIMULATOR_SCENE_H_
