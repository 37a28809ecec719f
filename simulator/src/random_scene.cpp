#include "bsls/simulator/random_scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <stdexcept>

#include "bsls/simulator/mesh.h"

namespace bsls::simulator {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// Nominal rig (thesis Table 2.2; RigParams in scene.h).
constexpr double kNominalProjectorHeightMm = 730.0;
constexpr double kNominalProjectorFocalD = 128.0;
constexpr double kNominalBaselineMm = 240.0;
constexpr double kNominalCameraHeightMm = 340.0;
// The largest tuning seed: the held-out set starts right after it.
constexpr std::uint32_t kTuningLastSeed = kHeldOutFirstSeed - 1;
// Share of the frames showing a face; the rest is split evenly over the objects.
constexpr double kFaceShare = 0.5;
// Image aspects (width / height) and their chances: square, landscape 4:3, portrait 3:4.
constexpr double kLandscapeChance = 0.2;
constexpr double kPortraitChance = 0.2;
// The pattern's strokes are w = d / 8: supersample thin strokes more (3 x 3
// below 1.25 px, 2 x 2 below 3 px, else 1: wide strokes gain little from it,
// and the largest frames would cost 4-9 times as much).
constexpr double kStrokePerPitch = 0.125;
// The exposure assumes blurred strokes peak at no less than this of an open slide.
constexpr double kMinStrokePeak = 0.3;
// Camera blur never drops below this (px): a real lens and sensor always blur.
constexpr double kMinCameraBlurPx = 0.3;
// Aim points drawn at most for line 0 to land within the central band of
// the image width (a share of the width).
constexpr int kFramingTries = 32;
constexpr double kLineZeroBand = 0.8;
// The bundled face's nose tip stands this share of its height above its back
// (0.567), a little more for a face pitched by 10 degrees.
constexpr double kNoseHeightPerFaceHeight = 0.6;
// Faces are subdivided this often (898 x 4^2 triangles, as the thesis scenes).
constexpr int kFaceSubdivision = 2;

bool Fail(std::string* error, const std::string& why) {
  if (error) *error = why;
  return false;
}

// Uniform draws from a 64-bit Mersenne twister, mapped to doubles here (not
// through std::uniform_real_distribution, whose output the standard leaves to
// the library): the same seed draws the same scene with every compiler.
class Draws {
 public:
  explicit Draws(std::uint32_t seed) : engine_(seed) {}
  // Uniform in [0, 1).
  double Unit() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Unit(); }
  double Uniform(const Interval& range) { return Uniform(range.min, range.max); }
  double Symmetric(double half) { return Uniform(-half, half); }
  double LogUniform(double lo, double hi) { return std::exp(Uniform(std::log(lo), std::log(hi))); }
  bool Chance(double p) { return Unit() < p; }
  // Uniform integer in [lo, hi].
  int Integer(int lo, int hi) {
    return lo + std::min(hi - lo, static_cast<int>(Unit() * (hi - lo + 1)));
  }

 private:
  std::mt19937_64 engine_;
};

// Device pose at `centre` looking at `target` (image up along world +y),
// then turned by small errors about its own x, y and z (roll) axes.
geometry::Pose DevicePose(const Eigen::Vector3d& centre, const Eigen::Vector3d& target,
                          double about_x_deg, double about_y_deg, double roll_deg) {
  const auto look = geometry::Pose::LookAt(centre, target, Eigen::Vector3d::UnitY());
  if (!look)
    throw std::invalid_argument("random scene: a device looks along world y or at its own centre");
  const Eigen::Matrix3d errors =
      (Eigen::AngleAxisd(roll_deg * kDegToRad, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(about_y_deg * kDegToRad, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(about_x_deg * kDegToRad, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  geometry::Pose pose;
  pose.rotation = errors * look->rotation;
  pose.translation = -pose.rotation * centre;
  return pose;
}

geometry::PinholeModel ProjectorModel(const Eigen::Vector3d& centre, double tilt_x_deg,
                                      double tilt_y_deg, double roll_deg, double focal_d,
                                      double k1) {
  geometry::Intrinsics in;
  in.fx = in.fy = focal_d;
  in.cx = in.cy = 0.0;
  in.k1 = k1;
  in.k2 = 0.0;
  const Eigen::Vector3d below = centre - Eigen::Vector3d::UnitZ();
  return geometry::PinholeModel(in, DevicePose(centre, below, tilt_x_deg, tilt_y_deg, roll_deg));
}

// Normalised image coordinates (x / z, y / z) of a world point in a device.
Eigen::Vector2d Normalised(const geometry::Pose& pose, const Eigen::Vector3d& world) {
  const Eigen::Vector3d d = pose.rotation * world + pose.translation;
  return d.head<2>() / d.z();
}

// The x at which slide coordinate s of `projector` is 0 along the line
// (x, y, z), by the secant method from x = 0. Throws when it does not converge.
double LineZeroX(const geometry::PinholeModel& projector, double y, double z) {
  auto s_at = [&](double x) {
    const auto st = projector.Project(Eigen::Vector3d(x, y, z));
    if (!st) throw std::invalid_argument("random scene: line 0 lies behind the projector");
    return st->x();
  };
  double x0 = 0.0, x1 = 10.0;
  double s0 = s_at(x0), s1 = s_at(x1);
  for (int i = 0; i < 50 && std::abs(s1) > 1e-10; ++i) {
    if (s1 == s0) break;
    const double x2 = x1 - s1 * (x1 - x0) / (s1 - s0);
    x0 = x1;
    s0 = s1;
    x1 = x2;
    s1 = s_at(x1);
  }
  if (!(std::abs(s1) <= 1e-6))
    throw std::invalid_argument("random scene: line 0 could not be found on the base plane");
  return x1;
}

// Where a ray meets the horizontal plane z = z_mm; nullopt when parallel or behind.
std::optional<Eigen::Vector3d> OnHorizontalPlane(const geometry::Ray& ray, double z_mm) {
  if (std::abs(ray.direction.z()) < 1e-12) return std::nullopt;
  const double t = (z_mm - ray.origin.z()) / ray.direction.z();
  if (t <= 0.0) return std::nullopt;
  return ray.At(t);
}

bool Ordered(const Interval& r) {
  return std::isfinite(r.min) && std::isfinite(r.max) && r.min <= r.max;
}

nlohmann::json Vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
nlohmann::json Vec(const Eigen::Vector2d& v) { return {v.x(), v.y()}; }

}  // namespace

std::string_view ToString(SeedSet set) { return set == SeedSet::kTuning ? "tuning" : "heldout"; }

SeedSet SetOfSeed(std::uint32_t seed) {
  if (seed == 0) throw std::invalid_argument("SetOfSeed: seed 0 belongs to no set");
  return seed <= kTuningLastSeed ? SeedSet::kTuning : SeedSet::kHeldOut;
}

std::uint32_t SeedOf(SeedSet set, int index) {
  if (index < 0) throw std::invalid_argument("SeedOf: index " + std::to_string(index) + " < 0");
  if (set == SeedSet::kTuning) {
    if (static_cast<std::uint32_t>(index) > kTuningLastSeed - kTuningFirstSeed)
      throw std::invalid_argument("SeedOf: the tuning set has only " +
                                  std::to_string(kTuningLastSeed) + " seeds");
    return kTuningFirstSeed + static_cast<std::uint32_t>(index);
  }
  if (static_cast<std::uint64_t>(index) + kHeldOutFirstSeed >
      std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("SeedOf: held-out index " + std::to_string(index) + " too large");
  return kHeldOutFirstSeed + static_cast<std::uint32_t>(index);
}

std::string_view ToString(RandomObject object) {
  switch (object) {
    case RandomObject::kFace:
      return "face";
    case RandomObject::kPlane:
      return "plane";
    case RandomObject::kRamp:
      return "ramp";
    case RandomObject::kBall:
      return "ball";
    case RandomObject::kBunny:
      return "bunny";
    case RandomObject::kCylinder:
      return "cylinder";
  }
  return "unknown";
}

bool RandomSceneRanges::IsValid(std::string* error) const {
  if (!(beyond_share >= 0.0 && beyond_share <= 1.0))
    return Fail(error, "random scene beyond_share must lie in [0, 1]");
  const std::pair<const char*, double> halves[] = {
      {"within_position_mm", within_position_mm},
      {"within_angle_deg", within_angle_deg},
      {"within_focal_d", within_focal_d},
      {"projector_offset_mm", projector_offset_mm},
      {"projector_tilt_deg", projector_tilt_deg},
      {"projector_roll_deg", projector_roll_deg},
      {"projector_k1", projector_k1},
      {"camera_offset_y_mm", camera_offset_y_mm},
      {"camera_aim_deg", camera_aim_deg},
      {"camera_roll_deg", camera_roll_deg},
      {"principal_point_fraction", principal_point_fraction},
      {"aspect_error", aspect_error},
      {"face_yaw_deg", face_yaw_deg},
      {"face_pitch_deg", face_pitch_deg},
      {"subject_offset_y_mm", subject_offset_y_mm},
      {"projector_focus_error_mm", projector_focus_error_mm}};
  for (const auto& [name, value] : halves)
    if (!(value >= 0.0 && std::isfinite(value)))
      return Fail(error, std::string("random scene ") + name + " must be non-negative and finite");
  const std::pair<const char*, Interval> ranges[] = {
      {"projector_height_mm", projector_height_mm},
      {"projector_focal_d", projector_focal_d},
      {"camera_baseline_mm", camera_baseline_mm},
      {"camera_height_mm", camera_height_mm},
      {"camera_k1", camera_k1},
      {"camera_k2", camera_k2},
      {"image_size_px", image_size_px},
      {"stripe_pitch_px", stripe_pitch_px},
      {"subject_fill", subject_fill},
      {"face_height_mm", face_height_mm},
      {"face_lift_mm", face_lift_mm},
      {"aim_offset_mm", aim_offset_mm},
      {"aim_height_mm", aim_height_mm},
      {"albedo_base", albedo_base},
      {"albedo_variation", albedo_variation},
      {"albedo_wavelength_mm", albedo_wavelength_mm},
      {"patch_albedo", patch_albedo},
      {"projector_blur_d", projector_blur_d},
      {"projector_aperture_mm", projector_aperture_mm},
      {"camera_blur_pitch", camera_blur_pitch},
      {"read_noise", read_noise},
      {"shot_noise", shot_noise},
      {"ambient", ambient},
      {"black_level", black_level},
      {"peak_grey", peak_grey}};
  for (const auto& [name, range] : ranges)
    if (!Ordered(range))
      return Fail(error, std::string("random scene ") + name + " must be finite with min <= max");
  if (projector_height_mm.min <= camera_height_mm.max)
    return Fail(error, "random scene projector_height_mm must lie above camera_height_mm");
  if (!(projector_focal_d.min > 0.0))
    return Fail(error, "random scene projector_focal_d must be > 0");
  if (!(camera_baseline_mm.min > 0.0))
    return Fail(error, "random scene camera_baseline_mm must be > 0");
  if (!(image_size_px.min >= 64.0 && image_size_px.max <= 8192.0))
    return Fail(error, "random scene image_size_px must lie within [64, 8192]");
  if (!(stripe_pitch_px.min >= 2.0))
    return Fail(error, "random scene stripe_pitch_px must be >= 2");
  if (!(subject_fill.min > 0.0 && subject_fill.max <= 2.0))
    return Fail(error, "random scene subject_fill must lie within (0, 2]");
  if (!(face_height_mm.min > 0.0)) return Fail(error, "random scene face_height_mm must be > 0");
  if (!(albedo_base.min > 0.0 && albedo_base.max <= 1.0))
    return Fail(error, "random scene albedo_base must lie within (0, 1]");
  if (!(albedo_variation.min >= 0.0 && albedo_variation.max < 1.0))
    return Fail(error, "random scene albedo_variation must lie within [0, 1)");
  if (!(albedo_wavelength_mm.min > 0.0))
    return Fail(error, "random scene albedo_wavelength_mm must be > 0");
  if (!(patch_albedo.min >= 0.0 && patch_albedo.max <= 1.0))
    return Fail(error, "random scene patch_albedo must lie within [0, 1]");
  if (max_dark_patches < 0 || max_dark_patches > 16)
    return Fail(error, "random scene max_dark_patches must lie in [0, 16]");
  if (!(projector_blur_d.min >= 0.0 && projector_blur_d.max <= 0.6))
    return Fail(error, "random scene projector_blur_d must lie within [0, 0.6] d");
  if (!(projector_aperture_mm.min >= 0.0))
    return Fail(error, "random scene projector_aperture_mm must be >= 0");
  if (!(camera_blur_pitch.min >= 0.0))
    return Fail(error, "random scene camera_blur_pitch must be >= 0");
  if (!(read_noise.min >= 0.0 && shot_noise.min >= 0.0 && ambient.min >= 0.0))
    return Fail(error, "random scene read_noise, shot_noise and ambient must be >= 0");
  if (!(black_level.min >= 0.0 && peak_grey.max <= 255.0 && peak_grey.min > black_level.max))
    return Fail(error, "random scene peak_grey must lie above black_level and within 255");
  return true;
}

geometry::PinholeModel RandomSceneDraw::Camera() const {
  geometry::Intrinsics in;
  in.fx = camera_fx;
  in.fy = camera_fy;
  in.cx = camera_cx;
  in.cy = camera_cy;
  in.k1 = camera_k1;
  in.k2 = camera_k2;
  return geometry::PinholeModel(in, DevicePose(camera_centre_mm, aim_point_mm, camera_aim_x_deg,
                                               camera_aim_y_deg, camera_roll_deg));
}

geometry::PinholeModel RandomSceneDraw::Projector() const {
  return ProjectorModel(projector_centre_mm, projector_tilt_x_deg, projector_tilt_y_deg,
                        projector_roll_deg, projector_focal_d, projector_k1);
}

std::string RandomSceneDraw::Describe() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << "seed " << seed << " (" << ToString(set) << ") " << ToString(object) << " "
      << pattern::ToString(side) << " " << width << "x" << height << " pitch " << stripe_pitch_px
      << " px fill " << subject_fill << (line_zero_framed ? "" : " (line 0 not framed)")
      << (beyond_tolerance ? " beyond" : " within") << ": projector dp " << projector_centre_mm.z()
      << " f " << projector_focal_d << " d tilt (" << projector_tilt_x_deg << ", "
      << projector_tilt_y_deg << ") roll " << projector_roll_deg << "; camera at ("
      << camera_centre_mm.x() << ", " << camera_centre_mm.y() << ", " << camera_centre_mm.z()
      << ") aim (" << camera_aim_x_deg << ", " << camera_aim_y_deg << ") roll " << camera_roll_deg
      << " f " << camera_fx;
  out.precision(3);
  out << " k1 " << camera_k1 << " k2 " << camera_k2;
  out.precision(1);
  out << "; subject " << subject_height_mm << " mm";
  if (object == RandomObject::kFace)
    out << " yaw " << face_yaw_deg << " pitch " << face_pitch_deg << " lift " << face_lift_mm;
  out.precision(2);
  out << "; albedo " << albedo.base << " +-" << albedo.variation << ", " << albedo.patches.size()
      << " patches; blur proj " << render.projector_blur_sigma_d << " d aperture "
      << render.projector_aperture_mm << " mm cam " << render.camera_blur_sigma_px << " px; noise "
      << render.noise_sigma << " shot " << render.shot_noise << "; ss " << render.supersampling;
  return out.str();
}

RandomSceneDraw DrawRandomScene(std::uint32_t seed, const RandomSceneRanges& ranges) {
  std::string error;
  if (!ranges.IsValid(&error)) throw std::invalid_argument("DrawRandomScene: " + error);
  if (seed == 0) throw std::invalid_argument("DrawRandomScene: seed 0 belongs to no set");
  Draws rng(seed);
  RandomSceneDraw d;
  d.seed = seed;
  d.set = SetOfSeed(seed);
  d.side = rng.Chance(0.5) ? pattern::Side::kLeft : pattern::Side::kRight;
  // The lit side's sign of world x.
  const double sign = d.side == pattern::Side::kLeft ? -1.0 : 1.0;
  if (rng.Chance(kFaceShare)) {
    d.object = RandomObject::kFace;
  } else {
    constexpr RandomObject kObjects[] = {RandomObject::kPlane, RandomObject::kRamp,
                                         RandomObject::kBall, RandomObject::kBunny,
                                         RandomObject::kCylinder};
    d.object = kObjects[rng.Integer(0, 4)];
  }
  d.beyond_tolerance = rng.Chance(ranges.beyond_share);
  const bool beyond = d.beyond_tolerance;
  const double pos = ranges.within_position_mm;
  const double ang = ranges.within_angle_deg;

  // Projector, in the nominal frame (its foot at the origin).
  Eigen::Vector3d projector_centre;
  if (beyond) {
    projector_centre = {rng.Symmetric(ranges.projector_offset_mm),
                        rng.Symmetric(ranges.projector_offset_mm),
                        rng.Uniform(ranges.projector_height_mm)};
    d.projector_tilt_x_deg = rng.Symmetric(ranges.projector_tilt_deg);
    d.projector_tilt_y_deg = rng.Symmetric(ranges.projector_tilt_deg);
    d.projector_roll_deg = rng.Symmetric(ranges.projector_roll_deg);
    d.projector_focal_d = rng.Uniform(ranges.projector_focal_d);
  } else {
    projector_centre = {rng.Symmetric(pos), rng.Symmetric(pos),
                        kNominalProjectorHeightMm + rng.Symmetric(pos)};
    d.projector_tilt_x_deg = rng.Symmetric(ang);
    d.projector_tilt_y_deg = rng.Symmetric(ang);
    d.projector_roll_deg = rng.Symmetric(ang);
    d.projector_focal_d = kNominalProjectorFocalD + rng.Symmetric(ranges.within_focal_d);
  }
  d.projector_k1 = rng.Symmetric(ranges.projector_k1);
  // Shift the world so that line 0 meets the base plane at x = 0 on y = 0.
  d.world_shift_x_mm =
      -LineZeroX(ProjectorModel(projector_centre, d.projector_tilt_x_deg, d.projector_tilt_y_deg,
                                d.projector_roll_deg, d.projector_focal_d, d.projector_k1),
                 0.0, 0.0);
  d.projector_centre_mm = projector_centre + Eigen::Vector3d(d.world_shift_x_mm, 0.0, 0.0);

  // Subject.
  d.subject_height_mm = rng.Uniform(ranges.face_height_mm);
  d.subject_centre_y_mm = rng.Symmetric(ranges.subject_offset_y_mm);

  // Camera of the drawn side.
  double baseline, height, offset_y;
  if (beyond) {
    baseline = rng.Uniform(ranges.camera_baseline_mm);
    height = rng.Uniform(ranges.camera_height_mm);
    offset_y = rng.Symmetric(ranges.camera_offset_y_mm);
    d.camera_aim_x_deg = rng.Symmetric(ranges.camera_aim_deg);
    d.camera_aim_y_deg = rng.Symmetric(ranges.camera_aim_deg);
    d.camera_roll_deg = rng.Symmetric(ranges.camera_roll_deg);
  } else {
    baseline = kNominalBaselineMm + rng.Symmetric(pos);
    height = kNominalCameraHeightMm + rng.Symmetric(pos);
    offset_y = rng.Symmetric(pos);
    d.camera_aim_x_deg = rng.Symmetric(ang);
    d.camera_aim_y_deg = rng.Symmetric(ang);
    d.camera_roll_deg = rng.Symmetric(ang);
  }
  d.camera_centre_mm = {d.projector_centre_mm.x() + sign * baseline,
                        d.projector_centre_mm.y() + offset_y, height};

  // Image and lens.
  d.height = static_cast<int>(
      std::lround(rng.LogUniform(ranges.image_size_px.min, ranges.image_size_px.max)));
  const double aspect_draw = rng.Unit();
  const double aspect = aspect_draw < kLandscapeChance                     ? 4.0 / 3.0
                        : aspect_draw < kLandscapeChance + kPortraitChance ? 3.0 / 4.0
                                                                           : 1.0;
  d.width = static_cast<int>(std::clamp<double>(
      std::lround(d.height * aspect), ranges.image_size_px.min, ranges.image_size_px.max));
  d.camera_k1 = rng.Uniform(ranges.camera_k1);
  d.camera_k2 = rng.Uniform(ranges.camera_k2);
  d.camera_cx = (d.width - 1) / 2.0 + rng.Symmetric(ranges.principal_point_fraction) * d.width;
  d.camera_cy = (d.height - 1) / 2.0 + rng.Symmetric(ranges.principal_point_fraction) * d.height;
  const double fy_over_fx = 1.0 + rng.Symmetric(ranges.aspect_error);

  // Aim point and focal length, drawn again (up to kFramingTries times)
  // until line 0 lands within the central kLineZeroBand of the image width:
  // the operator frames the profile line (thesis 2.6).
  const geometry::PinholeModel projector = d.Projector();
  for (int attempt = 0; attempt < kFramingTries; ++attempt) {
    d.aim_point_mm = {sign * rng.Uniform(ranges.aim_offset_mm), d.subject_centre_y_mm,
                      rng.Uniform(ranges.aim_height_mm)};
    // The stripe pitch and the subject's height per unit focal length, in
    // normalised coordinates at the aim point.
    const geometry::Pose camera_pose =
        DevicePose(d.camera_centre_mm, d.aim_point_mm, d.camera_aim_x_deg, d.camera_aim_y_deg,
                   d.camera_roll_deg);
    const Eigen::Vector3d& aim = d.aim_point_mm;
    const auto st = projector.Project(aim);
    if (!st) throw std::invalid_argument("DrawRandomScene: the aim point is behind the projector");
    const auto next_line =
        OnHorizontalPlane(projector.BackProject(Eigen::Vector2d(st->x() + 1.0, st->y())), aim.z());
    if (!next_line)
      throw std::invalid_argument("DrawRandomScene: the projector misses the subject");
    const double pitch_unit =
        (Normalised(camera_pose, aim) - Normalised(camera_pose, *next_line)).norm();
    const Eigen::Vector3d half_height(0.0, d.subject_height_mm / 2.0, 0.0);
    const double height_unit =
        (Normalised(camera_pose, aim + half_height) - Normalised(camera_pose, aim - half_height))
            .norm();
    const double pitch_per_fill = pitch_unit / height_unit * d.height;
    double lo = std::max(ranges.stripe_pitch_px.min, ranges.subject_fill.min * pitch_per_fill);
    double hi = std::min(ranges.stripe_pitch_px.max, ranges.subject_fill.max * pitch_per_fill);
    if (lo > hi) lo = hi = std::clamp(lo, ranges.stripe_pitch_px.min, ranges.stripe_pitch_px.max);
    d.stripe_pitch_px = rng.LogUniform(lo, hi);
    d.camera_fx = d.stripe_pitch_px / pitch_unit;
    d.camera_fy = d.camera_fx * fy_over_fx;
    d.subject_fill = d.camera_fx * height_unit / d.height;
    // Line 0 on the base plane and at a face's nose height, over the subject's height.
    const geometry::PinholeModel camera = d.Camera();
    bool framed = true;
    const double nose_mm = kNoseHeightPerFaceHeight * d.subject_height_mm + ranges.face_lift_mm.max;
    for (const double z : {0.0, nose_mm}) {
      for (const double dy : {-0.3, 0.0, 0.3}) {
        const double y = d.subject_centre_y_mm + dy * d.subject_height_mm;
        const auto image = camera.Project({LineZeroX(projector, y, z), y, z});
        framed = framed && image && std::abs(image->x() / d.width - 0.5) <= kLineZeroBand / 2.0;
      }
    }
    d.framing_tries = attempt + 1;
    d.line_zero_framed = framed;
    if (framed) break;
  }

  // Objects: every one is drawn, so that the draws of one do not move another's.
  d.face_yaw_deg = rng.Symmetric(ranges.face_yaw_deg);
  d.face_pitch_deg = rng.Symmetric(ranges.face_pitch_deg);
  d.face_lift_mm = rng.Uniform(ranges.face_lift_mm);
  d.plane_height_mm = rng.Uniform(0.0, 60.0);
  d.plane_tilt_deg = rng.Uniform(0.0, 8.0);
  d.plane_tilt_azimuth_deg = rng.Uniform(0.0, 360.0);
  {
    // Rising towards line 0 and the camera, like the thesis's ramp (scene.h).
    RampParams& ramp = d.ramp;
    ramp.slope_deg = rng.Uniform(25.0, 50.0);
    const double azimuth = rng.Symmetric(25.0);
    ramp.rise_azimuth_deg = sign < 0.0 ? azimuth : 180.0 - azimuth;
    ramp.run_mm = std::min(rng.Uniform(120.0, 160.0), 160.0 / std::tan(ramp.slope_deg * kDegToRad));
    ramp.width_mm = rng.Uniform(200.0, 260.0);
    ramp.foot_xy_mm = {sign * rng.Uniform(90.0, 130.0), d.subject_centre_y_mm};
  }
  {
    // A cap of a ball rising from the base plane.
    BallParams& ball = d.ball;
    ball.radius_mm = rng.Uniform(60.0, 130.0);
    const double cap = rng.Uniform(15.0, std::min(70.0, 0.8 * ball.radius_mm));
    ball.centre_mm = {sign * rng.Uniform(40.0, 90.0), d.subject_centre_y_mm + rng.Symmetric(30.0),
                      cap - ball.radius_mm};
    ball.cut_below_z_mm = 0.0;
  }
  d.bunny.mm_per_unit = rng.Uniform(9.0, 14.0);
  // BunnyParams mirrors x for the right side itself: keep it on the left here.
  d.bunny.centre_xy_mm = {-rng.Uniform(30.0, 70.0), d.subject_centre_y_mm + rng.Symmetric(20.0)};
  d.bunny_yaw_deg = rng.Uniform(0.0, 360.0);
  {
    // A log lying on (or sunk into) the base plane.
    CylinderParams& cylinder = d.cylinder;
    cylinder.radius_mm = rng.Uniform(25.0, 60.0);
    cylinder.length_mm = rng.Uniform(120.0, 220.0);
    const double azimuth = rng.Uniform(0.0, 180.0) * kDegToRad;
    cylinder.axis = {std::cos(azimuth), std::sin(azimuth), 0.0};
    cylinder.centre_mm = {sign * rng.Uniform(30.0, 70.0),
                          d.subject_centre_y_mm + rng.Symmetric(20.0),
                          rng.Uniform(0.3, 1.0) * cylinder.radius_mm};
    cylinder.caps = true;
    cylinder.cut_below_z_mm = 0.0;
  }

  // Albedo.
  d.albedo.base = rng.Uniform(ranges.albedo_base);
  d.albedo.variation = rng.Uniform(ranges.albedo_variation);
  d.albedo.wavelength_mm = rng.Uniform(ranges.albedo_wavelength_mm);
  d.albedo.seed = seed;
  const int patches = rng.Integer(0, ranges.max_dark_patches);
  for (int i = 0; i < patches; ++i) {
    AlbedoPatch patch;
    patch.centre_xy_mm = {sign * rng.Uniform(0.0, 80.0),
                          d.subject_centre_y_mm + rng.Symmetric(d.subject_height_mm / 2.0)};
    patch.semi_axis_x_mm = rng.Uniform(5.0, 25.0);
    patch.semi_axis_y_mm = rng.Uniform(3.0, 12.0);
    patch.rotation_deg = rng.Uniform(0.0, 180.0);
    patch.albedo = rng.Uniform(ranges.patch_albedo);
    patch.edge_mm = rng.Uniform(1.0, 5.0);
    d.albedo.patches.push_back(patch);
  }
  d.eyebrow_albedo = rng.Uniform(ranges.patch_albedo);

  // Light, defocus, noise.
  RenderParams& r = d.render;
  const double stroke_px = kStrokePerPitch * d.stripe_pitch_px;
  r.supersampling = stroke_px < 1.25 ? 3 : stroke_px < 3.0 ? 2 : 1;
  r.projector_blur_sigma_d = rng.Uniform(ranges.projector_blur_d);
  r.projector_aperture_mm = rng.Uniform(ranges.projector_aperture_mm);
  const double aim_depth =
      (projector.pose().rotation * d.aim_point_mm + projector.pose().translation).z();
  r.projector_focus_distance_mm =
      std::max(0.5 * aim_depth, aim_depth + rng.Symmetric(ranges.projector_focus_error_mm));
  r.camera_blur_sigma_px =
      std::max(kMinCameraBlurPx, rng.Uniform(ranges.camera_blur_pitch) * d.stripe_pitch_px);
  r.noise_sigma = rng.Uniform(ranges.read_noise);
  r.shot_noise = rng.Uniform(ranges.shot_noise);
  r.ambient = rng.Uniform(ranges.ambient);
  r.black_level = rng.Uniform(ranges.black_level);
  // Exposure: the operator sets the gain so that the strokes at the aim point
  // peak at `peak` grey levels. A stroke of width w blurred by sigma (slide
  // and camera blur, defocus at the aim point; in d) peaks at erf(w / (2
  // sqrt(2) sigma)) of an open slide.
  const double peak = rng.Uniform(ranges.peak_grey);
  const double focal_d = d.projector_focal_d;
  const double defocus_d = 0.25 * r.projector_aperture_mm * focal_d *
                           std::abs(aim_depth - r.projector_focus_distance_mm) /
                           (r.projector_focus_distance_mm * aim_depth);
  const double camera_blur_d = r.camera_blur_sigma_px / d.stripe_pitch_px;
  const double sigma_d = std::sqrt(r.projector_blur_sigma_d * r.projector_blur_sigma_d +
                                   defocus_d * defocus_d + camera_blur_d * camera_blur_d);
  const double stroke_peak = std::max(
      kMinStrokePeak, std::erf(kStrokePerPitch / (2.0 * std::sqrt(2.0) * std::max(sigma_d, 1e-9))));
  r.gain = (peak - r.black_level) / (d.albedo.base * (stroke_peak + r.ambient));
  r.seed = seed;
  return d;
}

RandomScene BuildRandomScene(const RandomSceneDraw& d, const RandomSceneData& data) {
  std::string error;
  if (!d.render.IsValid(&error)) throw std::invalid_argument("BuildRandomScene: " + error);
  RandomScene out;
  out.draw = d;
  out.render = d.render;
  Scene& scene = out.scene;
  scene.side = d.side;
  scene.slide = pattern::BrickSlideFor(d.side);
  scene.camera = d.Camera();
  scene.projector = d.Projector();
  scene.width = d.width;
  scene.height = d.height;
  AlbedoParams albedo = d.albedo;
  auto base_plane = std::make_shared<PlaneSurface>(PlaneSurface::Horizontal(0.0));
  switch (d.object) {
    case RandomObject::kFace: {
      FaceModelParams face_params;
      face_params.obj_path = data.face_obj;
      face_params.subdivision_levels = kFaceSubdivision;
      const IndexedMesh face = LoadFaceMesh(face_params);
      const Eigen::AlignedBox3d box = face.Bounds();
      const double scale = d.subject_height_mm / box.sizes().y();
      const Eigen::Matrix3d turn =
          (Eigen::AngleAxisd(d.face_pitch_deg * kDegToRad, Eigen::Vector3d::UnitX()) *
           Eigen::AngleAxisd(d.face_yaw_deg * kDegToRad, Eigen::Vector3d::UnitY()))
              .toRotationMatrix();
      // Scale and turn about the box centre, then lift the lowest point to
      // face_lift_mm and centre the box on the subject's y.
      Eigen::Affine3d transform = Eigen::Affine3d::Identity();
      transform.linear() = scale * turn;
      transform.translation() = -transform.linear() * box.center();
      IndexedMesh placed = Transformed(face, transform);
      const Eigen::AlignedBox3d turned = placed.Bounds();
      Eigen::Vector3d shift(0.0, d.subject_centre_y_mm - turned.center().y(),
                            d.face_lift_mm - turned.min().z());
      // The nose tip (LoadFaceMesh puts it at the largest z, on the midline)
      // onto line 0.
      Eigen::Vector3d nose = face.vertices.front();
      for (const auto& v : face.vertices)
        if (v.z() > nose.z()) nose = v;
      const Eigen::Vector3d nose_placed = transform * nose + shift;
      shift.x() = LineZeroX(scene.projector, nose_placed.y(), nose_placed.z()) - nose_placed.x();
      transform.pretranslate(shift);
      placed = Transformed(face, transform);
      // Eyebrows: painted where the face's brows went (centre on the surface
      // below the unplaced patch centre, moved with the face).
      const MeshSurface unplaced(face, "face");
      for (AlbedoPatch patch : FaceEyebrowPatches()) {
        geometry::Ray down;
        down.origin = {patch.centre_xy_mm.x(), patch.centre_xy_mm.y(), box.max().z() + 1.0};
        down.direction = -Eigen::Vector3d::UnitZ();
        const auto hit = unplaced.Intersect(down, std::numeric_limits<double>::infinity());
        const Eigen::Vector3d on_face =
            hit ? hit->point
                : Eigen::Vector3d(patch.centre_xy_mm.x(), patch.centre_xy_mm.y(), box.center().z());
        patch.centre_xy_mm = (transform * on_face).head<2>();
        patch.semi_axis_x_mm *= scale * std::cos(d.face_yaw_deg * kDegToRad);
        patch.semi_axis_y_mm *= scale * std::cos(d.face_pitch_deg * kDegToRad);
        patch.edge_mm *= scale;
        patch.albedo = d.eyebrow_albedo;
        albedo.patches.push_back(patch);
      }
      scene.surfaces = {std::make_shared<MeshSurface>(std::move(placed), "face"), base_plane};
      break;
    }
    case RandomObject::kPlane: {
      const double tilt = d.plane_tilt_deg * kDegToRad;
      const double azimuth = d.plane_tilt_azimuth_deg * kDegToRad;
      const Eigen::Vector3d normal(std::sin(tilt) * std::cos(azimuth),
                                   std::sin(tilt) * std::sin(azimuth), std::cos(tilt));
      scene.surfaces = {std::make_shared<PlaneSurface>(
          Eigen::Vector3d(0.0, d.subject_centre_y_mm, d.plane_height_mm), normal)};
      break;
    }
    case RandomObject::kRamp:
      scene.surfaces = {std::make_shared<RampSurface>(d.ramp), base_plane};
      break;
    case RandomObject::kBall:
      scene.surfaces = {std::make_shared<BallSurface>(d.ball), base_plane};
      break;
    case RandomObject::kBunny: {
      BunnyParams bunny = d.bunny;
      bunny.json_path = data.bunny_json;
      IndexedMesh mesh = LoadBunnyMesh(bunny, d.side);
      // Turn about the vertical through its bounding-box centre.
      const Eigen::Vector3d centre = mesh.Bounds().center();
      Eigen::Affine3d turn = Eigen::Affine3d::Identity();
      turn.translate(centre);
      turn.rotate(Eigen::AngleAxisd(d.bunny_yaw_deg * kDegToRad, Eigen::Vector3d::UnitZ()));
      turn.translate(-centre);
      scene.surfaces = {std::make_shared<MeshSurface>(Transformed(mesh, turn), "bunny"),
                        base_plane};
      break;
    }
    case RandomObject::kCylinder:
      scene.surfaces = {std::make_shared<CylinderSurface>(d.cylinder), base_plane};
      break;
  }
  scene.albedo = AlbedoField(albedo);
  if (!scene.IsValid(&error)) throw std::invalid_argument("BuildRandomScene: " + error);
  return out;
}

RandomScene MakeRandomScene(std::uint32_t seed, const RandomSceneData& data,
                            const RandomSceneRanges& ranges) {
  return BuildRandomScene(DrawRandomScene(seed, ranges), data);
}

nlohmann::json ToJson(const RandomSceneDraw& d) {
  const RenderParams& r = d.render;
  nlohmann::json patches = nlohmann::json::array();
  for (const AlbedoPatch& p : d.albedo.patches)
    patches.push_back({{"centre_xy_mm", Vec(p.centre_xy_mm)},
                       {"semi_axes_mm", {p.semi_axis_x_mm, p.semi_axis_y_mm}},
                       {"rotation_deg", p.rotation_deg},
                       {"albedo", p.albedo},
                       {"edge_mm", p.edge_mm}});
  return {{"seed", d.seed},
          {"set", std::string(ToString(d.set))},
          {"side", std::string(pattern::ToString(d.side))},
          {"object", std::string(ToString(d.object))},
          {"beyond_tolerance", d.beyond_tolerance},
          {"projector",
           {{"centre_mm", Vec(d.projector_centre_mm)},
            {"tilt_deg", {d.projector_tilt_x_deg, d.projector_tilt_y_deg}},
            {"roll_deg", d.projector_roll_deg},
            {"focal_d", d.projector_focal_d},
            {"k1", d.projector_k1},
            {"world_shift_x_mm", d.world_shift_x_mm}}},
          {"camera",
           {{"centre_mm", Vec(d.camera_centre_mm)},
            {"aim_point_mm", Vec(d.aim_point_mm)},
            {"aim_error_deg", {d.camera_aim_x_deg, d.camera_aim_y_deg}},
            {"roll_deg", d.camera_roll_deg},
            {"width", d.width},
            {"height", d.height},
            {"fx", d.camera_fx},
            {"fy", d.camera_fy},
            {"cx", d.camera_cx},
            {"cy", d.camera_cy},
            {"k1", d.camera_k1},
            {"k2", d.camera_k2},
            {"stripe_pitch_px", d.stripe_pitch_px},
            {"framing_tries", d.framing_tries},
            {"line_zero_framed", d.line_zero_framed},
            {"subject_fill", d.subject_fill}}},
          {"subject",
           {{"height_mm", d.subject_height_mm},
            {"centre_y_mm", d.subject_centre_y_mm},
            {"face_yaw_deg", d.face_yaw_deg},
            {"face_pitch_deg", d.face_pitch_deg},
            {"face_lift_mm", d.face_lift_mm}}},
          {"plane",
           {{"height_mm", d.plane_height_mm},
            {"tilt_deg", d.plane_tilt_deg},
            {"tilt_azimuth_deg", d.plane_tilt_azimuth_deg}}},
          {"ramp",
           {{"foot_xy_mm", Vec(d.ramp.foot_xy_mm)},
            {"rise_azimuth_deg", d.ramp.rise_azimuth_deg},
            {"slope_deg", d.ramp.slope_deg},
            {"run_mm", d.ramp.run_mm},
            {"width_mm", d.ramp.width_mm}}},
          {"ball", {{"centre_mm", Vec(d.ball.centre_mm)}, {"radius_mm", d.ball.radius_mm}}},
          {"bunny",
           {{"mm_per_unit", d.bunny.mm_per_unit},
            {"centre_xy_mm", Vec(d.bunny.centre_xy_mm)},
            {"yaw_deg", d.bunny_yaw_deg}}},
          {"cylinder",
           {{"centre_mm", Vec(d.cylinder.centre_mm)},
            {"axis", Vec(d.cylinder.axis)},
            {"radius_mm", d.cylinder.radius_mm},
            {"length_mm", d.cylinder.length_mm}}},
          {"albedo",
           {{"base", d.albedo.base},
            {"variation", d.albedo.variation},
            {"wavelength_mm", d.albedo.wavelength_mm},
            {"seed", d.albedo.seed},
            {"patches", patches},
            {"eyebrow_albedo", d.eyebrow_albedo}}},
          {"render",
           {{"supersampling", r.supersampling},
            {"projector_blur_sigma_d", r.projector_blur_sigma_d},
            {"projector_aperture_mm", r.projector_aperture_mm},
            {"projector_focus_distance_mm", r.projector_focus_distance_mm},
            {"camera_blur_sigma_px", r.camera_blur_sigma_px},
            {"noise_sigma", r.noise_sigma},
            {"shot_noise", r.shot_noise},
            {"ambient", r.ambient},
            {"black_level", r.black_level},
            {"gain", r.gain},
            {"seed", r.seed}}}};
}

}  // namespace bsls::simulator
