#include "bsls/simulator/scene.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace bsls::simulator {
namespace {

constexpr const char* kBunnyFileName = "stanford_bunny.json";
// Image sizes the rig accepts, pixels.
constexpr int kMinImageSize = 8;
constexpr int kMaxImageSize = 16384;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

Eigen::Vector3d MirrorX(const Eigen::Vector3d& v) { return {-v.x(), v.y(), v.z()}; }

// Lines of the brick slide are vertical; world "up" keeps image rows horizontal.
const Eigen::Vector3d kWorldUp = Eigen::Vector3d::UnitY();

}  // namespace

bool Scene::IsValid(std::string* error) const {
  if (surfaces.empty()) return Fail(error, "scene has no surfaces");
  for (const auto& surface : surfaces)
    if (!surface) return Fail(error, "scene holds a null surface");
  if (width < kMinImageSize || height < kMinImageSize || width > kMaxImageSize ||
      height > kMaxImageSize)
    return Fail(error, "scene image size must lie in [" + std::to_string(kMinImageSize) + ", " +
                           std::to_string(kMaxImageSize) + "] pixels");
  std::string why;
  if (!camera.intrinsics().IsValid(&why)) return Fail(error, "scene camera: " + why);
  if (!projector.intrinsics().IsValid(&why)) return Fail(error, "scene projector: " + why);
  if (!pattern.IsValid(&why)) return Fail(error, "scene pattern: " + why);
  const bool brick = slide == pattern::Slide::kLeftBrick || slide == pattern::Slide::kRightBrick;
  if (brick && slide != pattern::BrickSlideFor(side))
    return Fail(error, "scene slide " + std::to_string(static_cast<int>(slide)) +
                           " is not the brick slide of the " +
                           std::string(pattern::ToString(side)) + " side");
  return true;
}

std::optional<Hit> Scene::Intersect(const geometry::Ray& ray, double max_distance) const {
  std::optional<Hit> best;
  for (const auto& surface : surfaces) {
    if (auto hit = surface->Intersect(ray, max_distance)) {
      max_distance = hit->distance;
      best = hit;
    }
  }
  return best;
}

bool Scene::ProjectorReaches(const Eigen::Vector3d& point) const {
  geometry::Ray ray;
  ray.origin = projector.Centre();
  const Eigen::Vector3d to_point = point - ray.origin;
  const double distance = to_point.norm();
  if (distance <= kShadowToleranceMm) return true;
  ray.direction = to_point / distance;
  return !Intersect(ray, distance - kShadowToleranceMm).has_value();
}

std::optional<SurfaceSample> Scene::TraceCameraRay(const geometry::Ray& camera_ray) const {
  auto hit = Intersect(camera_ray, std::numeric_limits<double>::infinity());
  if (!hit) return std::nullopt;
  SurfaceSample sample;
  sample.hit = *hit;
  if (sample.hit.geometric_normal.dot(camera_ray.direction) > 0.0) {
    sample.hit.geometric_normal = -sample.hit.geometric_normal;
    sample.hit.normal = -sample.hit.normal;
  }
  const Eigen::Vector3d& point = sample.hit.point;
  const Eigen::Vector3d to_projector = projector.Centre() - point;
  sample.projector_distance_mm = to_projector.norm();
  const Eigen::Vector3d light = to_projector / sample.projector_distance_mm;
  sample.projector_depth_mm =
      (projector.pose().rotation * point + projector.pose().translation).z();
  sample.cos_incidence = sample.hit.normal.dot(light);
  const bool facing = sample.hit.geometric_normal.dot(light) > 0.0;
  if (facing && ProjectorReaches(point)) {
    if (auto st = projector.Project(point)) {
      sample.lit = true;
      sample.slide_st = *st;
    }
  }
  return sample;
}

std::string_view ToString(SurfaceKind kind) {
  switch (kind) {
    case SurfaceKind::kPlane:
      return "plane";
    case SurfaceKind::kRamp:
      return "ramp";
    case SurfaceKind::kBall:
      return "ball";
    case SurfaceKind::kFace:
      return "face";
    case SurfaceKind::kBunny:
      return "bunny";
  }
  return "unknown";
}

std::optional<SurfaceKind> ParseSurfaceKind(std::string_view text) {
  for (const SurfaceKind kind : {SurfaceKind::kPlane, SurfaceKind::kRamp, SurfaceKind::kBall,
                                 SurfaceKind::kFace, SurfaceKind::kBunny})
    if (text == ToString(kind)) return kind;
  return std::nullopt;
}

bool RigParams::IsValid(std::string* error) const {
  if (!projector_centre_mm.allFinite() || !projector_target_mm.allFinite())
    return Fail(error, "rig projector centre and target must be finite");
  if (!(projector_focal_d > 0.0 && std::isfinite(projector_focal_d)))
    return Fail(error, "rig projector_focal_d must be positive and finite");
  if (!std::isfinite(projector_k1)) return Fail(error, "rig projector_k1 must be finite");
  if (!left_camera_centre_mm.allFinite() || !left_camera_target_mm.allFinite())
    return Fail(error, "rig camera centre and target must be finite");
  if (!(camera_focal_per_height > 0.0 && std::isfinite(camera_focal_per_height)))
    return Fail(error, "rig camera_focal_per_height must be positive and finite");
  if (!std::isfinite(camera_k1) || !std::isfinite(camera_k2))
    return Fail(error, "rig camera distortion must be finite");
  if (width < kMinImageSize || height < kMinImageSize || width > kMaxImageSize ||
      height > kMaxImageSize)
    return Fail(error, "rig image size must lie in [" + std::to_string(kMinImageSize) + ", " +
                           std::to_string(kMaxImageSize) + "] pixels");
  if (!geometry::Pose::LookAt(projector_centre_mm, projector_target_mm, kWorldUp))
    return Fail(error, "rig projector must not look along world y or at its own centre");
  if (!geometry::Pose::LookAt(left_camera_centre_mm, left_camera_target_mm, kWorldUp))
    return Fail(error, "rig camera must not look along world y or at its own centre");
  return true;
}

geometry::PinholeModel MakeProjector(const RigParams& rig) {
  std::string error;
  if (!rig.IsValid(&error)) throw std::invalid_argument(error);
  geometry::Intrinsics in;
  in.fx = in.fy = rig.projector_focal_d;
  in.cx = in.cy = 0.0;
  in.k1 = rig.projector_k1;
  in.k2 = 0.0;
  return geometry::PinholeModel(
      in, *geometry::Pose::LookAt(rig.projector_centre_mm, rig.projector_target_mm, kWorldUp));
}

geometry::PinholeModel MakeCamera(const RigParams& rig, pattern::Side side) {
  std::string error;
  if (!rig.IsValid(&error)) throw std::invalid_argument(error);
  geometry::Intrinsics in;
  in.fx = in.fy = rig.camera_focal_per_height * rig.height;
  in.cx = (rig.width - 1) / 2.0;
  in.cy = (rig.height - 1) / 2.0;
  in.k1 = rig.camera_k1;
  in.k2 = rig.camera_k2;
  const bool left = side == pattern::Side::kLeft;
  const Eigen::Vector3d eye = left ? rig.left_camera_centre_mm : MirrorX(rig.left_camera_centre_mm);
  const Eigen::Vector3d target =
      left ? rig.left_camera_target_mm : MirrorX(rig.left_camera_target_mm);
  return geometry::PinholeModel(in, *geometry::Pose::LookAt(eye, target, kWorldUp));
}

bool FaceModelParams::IsValid(std::string* error) const {
  if (subdivision_levels < 0 || subdivision_levels > 4)
    return Fail(error, "face subdivision_levels must lie in [0, 4]");
  if (!(mm_per_unit > 0.0 && std::isfinite(mm_per_unit)))
    return Fail(error, "face mm_per_unit must be positive and finite");
  return true;
}

IndexedMesh LoadFaceMesh(const FaceModelParams& params) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument(error);
  const std::filesystem::path path =
      params.obj_path.empty() ? DefaultDataDir() / kFaceFileName : params.obj_path;
  IndexedMesh mesh = LoadObj(path);
  if (!mesh.IsValid(&error)) throw MeshLoadError(path, error);
  mesh = LoopSubdivide(mesh, params.subdivision_levels);
  for (auto& v : mesh.vertices) v *= params.mm_per_unit;
  const Eigen::AlignedBox3d box = mesh.Bounds();
  Eigen::Vector3d nose = mesh.vertices.front();
  for (const auto& v : mesh.vertices)
    if (v.z() > nose.z()) nose = v;
  const Eigen::Vector3d shift(-nose.x(), -(box.min().y() + box.max().y()) / 2.0, -box.min().z());
  for (auto& v : mesh.vertices) v += shift;
  return mesh;
}

std::vector<AlbedoPatch> FaceEyebrowPatches() {
  // Measured on the bundled face placed by LoadFaceMesh: the brows sit about
  // 14 mm above the eye centres (x = +-30 mm, y = 31 mm), outer ends lower.
  AlbedoPatch left;
  left.centre_xy_mm = {-33.0, 45.0};
  left.semi_axis_x_mm = 22.0;
  left.semi_axis_y_mm = 5.5;
  left.rotation_deg = 8.0;
  left.albedo = 0.3;
  left.edge_mm = 4.0;
  AlbedoPatch right = left;
  right.centre_xy_mm.x() = -left.centre_xy_mm.x();
  right.rotation_deg = -left.rotation_deg;
  return {left, right};
}

bool BunnyParams::IsValid(std::string* error) const {
  if (!(mm_per_unit > 0.0 && std::isfinite(mm_per_unit)))
    return Fail(error, "bunny mm_per_unit must be positive and finite");
  if (!centre_xy_mm.allFinite()) return Fail(error, "bunny centre_xy_mm must be finite");
  if (subdivision_levels < 0 || subdivision_levels > 3)
    return Fail(error, "bunny subdivision_levels must lie in [0, 3]");
  return true;
}

IndexedMesh LoadBunnyMesh(const BunnyParams& params, pattern::Side side) {
  std::string error;
  if (!params.IsValid(&error)) throw std::invalid_argument(error);
  const std::filesystem::path path =
      params.json_path.empty() ? DefaultDataDir() / kBunnyFileName : params.json_path;
  IndexedMesh mesh = LoadMeshJson(path);
  if (!mesh.IsValid(&error)) throw MeshLoadError(path, error);
  mesh = LoopSubdivide(mesh, params.subdivision_levels);
  // File (x, y, z) -> world (x, -z, y): a proper rotation, winding kept.
  for (auto& v : mesh.vertices) v = Eigen::Vector3d(v.x(), -v.z(), v.y()) * params.mm_per_unit;
  const Eigen::AlignedBox3d box = mesh.Bounds();
  const double centre_x =
      side == pattern::Side::kLeft ? params.centre_xy_mm.x() : -params.centre_xy_mm.x();
  const Eigen::Vector3d shift(centre_x - box.center().x(),
                              params.centre_xy_mm.y() - box.center().y(), -box.min().z());
  for (auto& v : mesh.vertices) v += shift;
  return mesh;
}

bool ThesisSceneOptions::IsValid(std::string* error) const {
  std::string why;
  if (!rig.IsValid(&why)) return Fail(error, why);
  if (!pattern.IsValid(&why)) return Fail(error, "pattern: " + why);
  if (!face.IsValid(&why)) return Fail(error, why);
  if (!ramp.IsValid(&why)) return Fail(error, why);
  if (!ball.IsValid(&why)) return Fail(error, why);
  if (!bunny.IsValid(&why)) return Fail(error, why);
  if (!albedo.IsValid(&why)) return Fail(error, why);
  for (std::size_t i = 0; i < face_lesions.size(); ++i)
    if (!face_lesions[i].IsValid(&why))
      return Fail(error, "face lesion " + std::to_string(i) + ": " + why);
  return true;
}

Scene ThesisScene(pattern::Side side, SurfaceKind kind, const ThesisSceneOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("ThesisScene: " + error);
  const bool left = side == pattern::Side::kLeft;
  Scene scene;
  scene.side = side;
  scene.slide =
      options.reference_cross ? pattern::Slide::kReferenceCross : pattern::BrickSlideFor(side);
  scene.pattern = options.pattern;
  scene.camera = MakeCamera(options.rig, side);
  scene.projector = MakeProjector(options.rig);
  scene.width = options.rig.width;
  scene.height = options.rig.height;
  AlbedoParams albedo = options.albedo;
  auto base_plane = std::make_shared<PlaneSurface>(PlaneSurface::Horizontal(0.0));
  switch (kind) {
    case SurfaceKind::kPlane:
      scene.surfaces = {base_plane};
      break;
    case SurfaceKind::kRamp: {
      RampParams ramp = options.ramp;
      if (!left) {
        ramp.foot_xy_mm.x() = -ramp.foot_xy_mm.x();
        ramp.rise_azimuth_deg = 180.0 - ramp.rise_azimuth_deg;
      }
      scene.surfaces = {std::make_shared<RampSurface>(ramp), base_plane};
      break;
    }
    case SurfaceKind::kBall: {
      BallParams ball = options.ball;
      if (!left) ball.centre_mm = MirrorX(ball.centre_mm);
      scene.surfaces = {std::make_shared<BallSurface>(ball), base_plane};
      break;
    }
    case SurfaceKind::kFace: {
      std::shared_ptr<const Surface> face =
          std::make_shared<MeshSurface>(LoadFaceMesh(options.face), "face");
      if (!options.face_lesions.empty())
        face = std::make_shared<LesionSurface>(std::move(face), options.face_lesions);
      scene.surfaces = {std::move(face)};
      if (options.face_on_base_plane) scene.surfaces.push_back(base_plane);
      if (options.face_eyebrows)
        for (const AlbedoPatch& patch : FaceEyebrowPatches()) albedo.patches.push_back(patch);
      break;
    }
    case SurfaceKind::kBunny:
      scene.surfaces = {std::make_shared<MeshSurface>(LoadBunnyMesh(options.bunny, side), "bunny"),
                        base_plane};
      break;
  }
  scene.albedo = AlbedoField(albedo);
  return scene;
}

}  // namespace bsls::simulator
