// CalibrateSide on simulated sessions against the simulator's truth (thesis
// chapter 6; acceptance figures of the calibration issue on the thesis rig,
// Tables 2.1 / 2.2), and its errors on bad sessions.
#include "bsls/calibration/side_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <string>

#include "bsls/calibration/calibration_file.h"
#include "bsls/calibration/calibration_report.h"
#include "bsls/calibration/projector_calibration.h"
#include "bsls/io/frame_file.h"
#include "bsls/simulator/calibration_session.h"
#include "bsls/simulator/renderer.h"
#include "bsls/testing/calibration_sessions.h"

namespace bsls::calibration {
namespace {

using pattern::Side;
using testing::SessionKind;

// Acceptance figures.
constexpr double kMaxRmsCleanPx = 0.1;        // camera reprojection RMS, no noise
constexpr double kMaxRmsNoisyPx = 0.3;        // camera reprojection RMS, noise sigma 2
constexpr double kMaxPlaneRmsMm = 0.1;        // perspective light-plane residual
constexpr double kProjectorDistanceMm = 2.0;  // recovered vs true projector-to-origin distance
// Against the truth.
constexpr double kCameraCentreMm = 1.0;        // recovered camera centre
constexpr double kFocalRelative = 2e-3;        // fx, fy
constexpr double kVolumeReprojectionPx = 0.2;  // camera model over the face volume, worst point
constexpr double kLightPlaneMm = 0.1;          // fitted vs true light plane, working volume
constexpr double kProjectorCentreMm = 2.0;     // projector matrix centre
constexpr double kSlideRowD = 0.1;             // projector principal point t: rows absolute
constexpr double kReferenceRayMm = 0.1;        // fitted vs true ray of slide point (0, 0)

const simulator::CalibrationSessionParams& Params(SessionKind kind) {
  static const auto left = testing::SessionParams(SessionKind::kLeftNoisy);
  static const auto right = testing::SessionParams(SessionKind::kRightClean);
  return kind == SessionKind::kLeftNoisy ? left : right;
}

std::string Name(SessionKind kind) {
  return kind == SessionKind::kLeftNoisy ? "LeftNoise2" : "RightNoNoise";
}

// Points of the side's half of the face volume (rig frame: |x| <= 90 mm on
// the side's half and 10 mm over the midline, |y| <= 90 mm, z 0 .. 100 mm) in
// the calibration world frame, where the true camera sees them.
std::vector<Eigen::Vector3d> FaceVolume(SessionKind kind, const geometry::PinholeModel& camera,
                                        int width, int height) {
  const auto& params = Params(kind);
  const double sign = testing::SideOf(kind) == Side::kLeft ? -1.0 : 1.0;
  std::vector<Eigen::Vector3d> points;
  for (double x = -10.0; x <= 90.0; x += 10.0)
    for (double y = -90.0; y <= 90.0; y += 10.0)
      for (double z = 0.0; z <= 100.0; z += 20.0) {
        const Eigen::Vector3d world = simulator::RigToCalibrationWorld(params, {sign * x, y, z});
        const auto image = camera.Project(world);
        if (image && image->x() >= 0 && image->y() >= 0 && image->x() <= width - 1 &&
            image->y() <= height - 1)
          points.push_back(world);
      }
  return points;
}

class SimulatedSession : public ::testing::TestWithParam<SessionKind> {};

TEST_P(SimulatedSession, MeetsTheAcceptanceFigures) {
  const SessionKind kind = GetParam();
  const SideCalibration& c = testing::SessionCalibration(kind);
  const geometry::PinholeModel projector = simulator::CalibrationProjector(Params(kind));
  const double max_rms = kind == SessionKind::kLeftNoisy ? kMaxRmsNoisyPx : kMaxRmsCleanPx;
  EXPECT_EQ(c.side, testing::SideOf(kind));
  EXPECT_TRUE(c.dropped_views.empty()) << c.dropped_views.front().reason;
  EXPECT_LE(c.camera.report.rms_px, max_rms);
  EXPECT_LE(c.perspective.report.rms_mm, kMaxPlaneRmsMm);
  ASSERT_TRUE(c.projector_matrix.has_value());
  const double true_distance = projector.Centre().norm();
  EXPECT_NEAR(*c.projector.matrix_centre_distance_mm, true_distance, kProjectorDistanceMm);
  EXPECT_LT((*c.projector.matrix_centre_mm - projector.Centre()).norm(), kProjectorCentreMm);
  // The perspective model's centre lies on the pencil axis through the true
  // centre (the stripes cannot say where on it).
  const Eigen::Vector3d off = projector.Centre() - c.perspective.model.centre_mm;
  EXPECT_LT((off - off.dot(c.perspective.model.axis_direction) * c.perspective.model.axis_direction)
                .norm(),
            kProjectorCentreMm);
  std::cout << "[ figures  ] " << Name(kind) << ": camera RMS " << c.camera.report.rms_px
            << " px / " << c.camera.report.rms_mm << " mm, plane RMS "
            << c.perspective.report.rms_mm << " mm (parallel " << c.parallel.report.rms_mm
            << " mm), projector distance " << *c.projector.matrix_centre_distance_mm << " mm (true "
            << true_distance << ", error " << *c.projector.matrix_centre_distance_mm - true_distance
            << "), stripe centre " << c.sigmas.stripe_centre_px << " px, CalibrateSide "
            << c.diagnostics.times.total_ms << " ms\n";
  RecordProperty("camera_rms_px", std::to_string(c.camera.report.rms_px));
  RecordProperty("plane_rms_mm", std::to_string(c.perspective.report.rms_mm));
  RecordProperty("projector_distance_error_mm",
                 std::to_string(*c.projector.matrix_centre_distance_mm - true_distance));
}

TEST_P(SimulatedSession, CameraMatchesTheTruthOverTheFaceVolume) {
  const SessionKind kind = GetParam();
  const SideCalibration& c = testing::SessionCalibration(kind);
  const geometry::PinholeModel truth =
      simulator::CalibrationCamera(Params(kind), testing::SideOf(kind));
  EXPECT_LT((c.camera.model.Centre() - truth.Centre()).norm(), kCameraCentreMm);
  EXPECT_NEAR(c.camera.model.intrinsics().fx, truth.intrinsics().fx,
              kFocalRelative * truth.intrinsics().fx);
  EXPECT_NEAR(c.camera.model.intrinsics().fy, truth.intrinsics().fy,
              kFocalRelative * truth.intrinsics().fy);
  // Beyond the target's positions: the whole half face, where distortion
  // fitted on the target must still hold.
  const auto volume = FaceVolume(kind, truth, c.width, c.height);
  ASSERT_GT(volume.size(), 500u);
  double worst = 0.0, sum2 = 0.0;
  for (const Eigen::Vector3d& p : volume) {
    const double e = (*c.camera.model.Project(p) - *truth.Project(p)).norm();
    worst = std::max(worst, e);
    sum2 += e * e;
  }
  EXPECT_LT(worst, kVolumeReprojectionPx);
  std::cout << "[ figures  ] " << Name(kind) << ": camera centre off "
            << (c.camera.model.Centre() - truth.Centre()).norm() << " mm, fx "
            << c.camera.model.intrinsics().fx << " (true " << truth.intrinsics().fx
            << "), face volume reprojection RMS " << std::sqrt(sum2 / volume.size()) << " px, max "
            << worst << " px over " << volume.size() << " points\n";
}

// Largest distance (mm) of the true light planes of lines 0, 3, 7, 12, 19
// from the perspective model's and the projector matrix's planes, over the
// working range (z 0-120 mm). `c` must have a projector matrix.
struct LightPlaneError {
  double perspective = 0.0;
  double matrix = 0.0;
};

LightPlaneError LightPlanesOffTheTruth(SessionKind kind, const SideCalibration& c) {
  const Side side = testing::SideOf(kind);
  const geometry::PinholeModel projector = simulator::CalibrationProjector(Params(kind));
  double worst_perspective = 0.0, worst_matrix = 0.0;
  for (const int e : {0, 3, 7, 12, 19}) {
    const double s = pattern::SFromU(side, e);
    const LightPlane truth = LightPlaneOfSlideColumn(projector, s);
    const LightPlane perspective = c.perspective.model.PlaneOfLine(e);
    const LightPlane matrix = LightPlaneOfSlideColumn(c.projector_matrix->model, s);
    // Points of the true plane over the working range: the slide column's
    // rays between rows -20 .. 20 where they cross z = 0 .. 120 mm.
    for (double t = -20.0; t <= 20.0; t += 5.0) {
      const geometry::Ray ray = projector.BackProject({s, t});
      for (double z = 0.0; z <= 120.0; z += 30.0) {
        const Eigen::Vector3d p = ray.At((z - ray.origin.z()) / ray.direction.z());
        EXPECT_LT(std::abs(truth.SignedDistance(p)), 1e-6);
        worst_perspective = std::max(worst_perspective, std::abs(perspective.SignedDistance(p)));
        worst_matrix = std::max(worst_matrix, std::abs(matrix.SignedDistance(p)));
      }
    }
  }
  return {worst_perspective, worst_matrix};
}

TEST_P(SimulatedSession, LightPlanesMatchTheTrueProjector) {
  const SessionKind kind = GetParam();
  const SideCalibration& c = testing::SessionCalibration(kind);
  ASSERT_TRUE(c.projector_matrix.has_value());
  const LightPlaneError off = LightPlanesOffTheTruth(kind, c);
  EXPECT_LT(off.perspective, kLightPlaneMm);
  EXPECT_LT(off.matrix, kLightPlaneMm);
  std::cout << "[ figures  ] " << Name(kind) << ": light planes off the truth by at most "
            << off.perspective << " mm (perspective model), " << off.matrix
            << " mm (projector matrix)\n";
}

TEST_P(SimulatedSession, CrossesMakeTheSlideRowsAbsolute) {
  const SessionKind kind = GetParam();
  const SideCalibration& c = testing::SessionCalibration(kind);
  const geometry::PinholeModel projector = simulator::CalibrationProjector(Params(kind));
  for (const ScreenViewReport& v : c.screen_views) {
    ASSERT_TRUE(v.q_offset.has_value()) << v.image;
    EXPECT_EQ(*v.q_offset % 2, 0);
    EXPECT_GT(v.matrix_junctions, 100) << v.image;
  }
  // The cross centres lie on the true ray of slide point (0, 0).
  ASSERT_TRUE(c.reference_ray.has_value());
  const geometry::Ray truth = projector.BackProject({0.0, 0.0});
  for (const double z : {0.0, 60.0, 120.0}) {
    const Eigen::Vector3d expected = truth.At((z - truth.origin.z()) / truth.direction.z());
    EXPECT_LT((*c.reference_ray->AtZ(z) - expected).norm(), kReferenceRayMm) << z;
  }
  // Rows off by an even number would move the projector's principal point
  // along t by that many pitches.
  ASSERT_TRUE(c.projector_matrix.has_value());
  EXPECT_NEAR(c.projector_matrix->model.intrinsics().cy, projector.intrinsics().cy, kSlideRowD);
  EXPECT_NEAR(c.projector_matrix->model.intrinsics().cx, projector.intrinsics().cx, kSlideRowD);
}

INSTANTIATE_TEST_SUITE_P(ThesisRig, SimulatedSession,
                         ::testing::Values(SessionKind::kLeftNoisy, SessionKind::kRightClean),
                         [](const auto& test_info) { return Name(test_info.param); });

// ------------------------------------------------------------- bad sessions

// The left session's manifest with some views changed in memory.
Manifest LeftManifest() { return testing::SessionManifest(SessionKind::kLeftNoisy); }

// Runs CalibrateSide expecting a CalibrationError; returns it.
CalibrationError FailureOf(const Manifest& manifest, const SideCalibrationParams& params = {}) {
  try {
    CalibrateSide(manifest, params);
  } catch (const CalibrationError& e) {
    return e;
  }
  ADD_FAILURE() << "CalibrateSide accepted the session";
  return CalibrationError(CalibrationErrorReason::kInvalidInput, "");
}

TEST(SideCalibrationErrors, MissingImageIsNamed) {
  Manifest manifest = LeftManifest();
  manifest.screen_views[1].image = manifest.path.parent_path() / "no_such_screen.png";
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kUnreadableInput);
  EXPECT_NE(std::string(e.what()).find("no_such_screen.png"), std::string::npos) << e.what();
}

TEST(SideCalibrationErrors, CameraViewsOutOfZOrder) {
  Manifest manifest = LeftManifest();
  std::swap(manifest.camera_views[1], manifest.camera_views[2]);
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kInvalidInput);
  EXPECT_NE(std::string(e.what()).find("not in increasing z"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find(manifest.path.string()), std::string::npos) << e.what();
}

TEST(SideCalibrationErrors, TooFewViews) {
  Manifest manifest = LeftManifest();
  manifest.camera_views.resize(2);
  CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kInvalidInput);
  EXPECT_NE(std::string(e.what()).find("2 camera views; at least 3"), std::string::npos)
      << e.what();
  manifest = LeftManifest();
  manifest.screen_views.resize(2);
  e = FailureOf(manifest);
  EXPECT_NE(std::string(e.what()).find("2 screen views; at least 3"), std::string::npos)
      << e.what();
  manifest = LeftManifest();
  manifest.reference_views.resize(1);
  e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kInvalidInput);
  EXPECT_NE(std::string(e.what()).find("1 reference views; none or at least 2"), std::string::npos)
      << e.what();
}

// With three crosses, one off the line could be any of them: refused.
TEST(SideCalibrationErrors, MisreportedCrossDepthAmongThreeIsRefused) {
  Manifest manifest = LeftManifest();
  manifest.reference_views[1].z_mm += 10.0;  // the cross centre leaves the projector ray
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kInvalidInput);
  EXPECT_NE(std::string(e.what()).find("off the line through the other cross centres"),
            std::string::npos)
      << e.what();
  EXPECT_NE(std::string(e.what()).find("with 3 crosses"), std::string::npos) << e.what();
}

TEST(SideCalibrationErrors, CameraThatDoesNotConverge) {
  SideCalibrationParams params;
  params.camera.max_iterations = 1;
  const CalibrationError e = FailureOf(LeftManifest(), params);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kNotConverged);
  EXPECT_NE(std::string(e.what()).find("did not converge"), std::string::npos) << e.what();
}

TEST(SideCalibrationErrors, InvalidParamsNameTheField) {
  SideCalibrationParams params;
  std::string why;
  EXPECT_TRUE(params.IsValid(&why)) << why;
  params.decode.q_offset = 2;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("q_offset"), std::string::npos) << why;
  params = {};
  params.min_screen_views = 1;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("min_screen_views"), std::string::npos) << why;
  EXPECT_EQ(FailureOf(LeftManifest(), params).reason(), CalibrationErrorReason::kInvalidParams);
}

TEST(SideCalibration, WithoutCrossesTheRowsStayRelativeAndNoMatrixIsFitted) {
  Manifest manifest = LeftManifest();
  manifest.reference_views.clear();
  const SideCalibration c = CalibrateSide(manifest);
  EXPECT_FALSE(c.projector_matrix.has_value());
  EXPECT_FALSE(c.reference_ray.has_value());
  for (const ScreenViewReport& v : c.screen_views) EXPECT_FALSE(v.q_offset.has_value());
  EXPECT_LE(c.perspective.report.rms_mm, kMaxPlaneRmsMm);
  EXPECT_FALSE(c.projector.matrix_centre_mm.has_value());
}

// ------------------------------------------------------ views that fail

// A grey image of the session's size with neither target, bricks nor cross:
// uniform noise, in the test's temporary folder.
std::filesystem::path NoiseImage(const Manifest& manifest) {
  const cv::Mat like = io::LoadGreyFrame(manifest.camera_views[0].image.string());
  cv::Mat noise(like.size(), CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  const std::filesystem::path path =
      std::filesystem::path(::testing::TempDir()) / "bsls_side_calibration_noise.png";
  io::WritePngAtomically(path.string(), noise);
  return path;
}

// The dropped view of `kind` at `index`, or nullptr.
const DroppedView* Dropped(const SideCalibration& c, ViewKind kind, int index) {
  for (const DroppedView& d : c.dropped_views)
    if (d.kind == kind && d.index == index) return &d;
  return nullptr;
}

// True when no used view of the calibration reads `image`.
bool Unused(const SideCalibration& c, const std::filesystem::path& image, double z_mm) {
  for (const auto& v : c.camera_views)
    if (v.image == image && v.z_mm == z_mm) return false;
  for (const auto& v : c.screen_views)
    if (v.image == image && v.z_mm == z_mm) return false;
  for (const auto& v : c.reference_views)
    if (v.image == image && v.z_mm == z_mm) return false;
  return true;
}

TEST(SideCalibrationDropsAView, ACameraViewWithoutTheTarget) {
  Manifest manifest = LeftManifest();
  const std::filesystem::path bricks = manifest.screen_views[0].image;
  manifest.camera_views[3].image = bricks;  // bricks, no target
  const SideCalibration c = CalibrateSide(manifest);
  ASSERT_EQ(c.dropped_views.size(), 1u);
  const DroppedView* d = Dropped(c, ViewKind::kCamera, 3);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->image, bricks);
  EXPECT_EQ(d->z_mm, manifest.camera_views[3].z_mm);
  EXPECT_NE(d->reason.find("target not found"), std::string::npos) << d->reason;
  EXPECT_EQ(c.camera_views.size(), manifest.camera_views.size() - 1);
  EXPECT_TRUE(Unused(c, bricks, manifest.camera_views[3].z_mm));
  // The five views left still give the camera.
  const geometry::PinholeModel truth =
      simulator::CalibrationCamera(Params(SessionKind::kLeftNoisy), Side::kLeft);
  EXPECT_LE(c.camera.report.rms_px, kMaxRmsNoisyPx);
  EXPECT_LT((c.camera.model.Centre() - truth.Centre()).norm(), kCameraCentreMm);
  EXPECT_NEAR(c.camera.model.intrinsics().fx, truth.intrinsics().fx,
              kFocalRelative * truth.intrinsics().fx);
  for (const CameraViewReport& v : c.camera_views) EXPECT_GT(v.rms_px, 0.0) << v.image;
}

// The caller is asked before every view and inside each view's decode: the
// question after the camera views' and the first screen view's own comes
// from inside that screen view's decode, and stops the calibration there.
TEST(SideCalibration, StopsInsideAViewsDecodeWhenAsked) {
  const Manifest manifest = LeftManifest();
  const int before_decode = static_cast<int>(manifest.camera_views.size()) + 1;
  int asked = 0;
  const Cancellation stop([&] { return ++asked > before_decode; });
  try {
    CalibrateSide(manifest, {}, {}, stop);
    ADD_FAILURE() << "the calibration ran to its end";
  } catch (const Cancelled& e) {
    EXPECT_EQ(asked, before_decode + 1);
    // Not a view's name: a stage of the decode.
    EXPECT_EQ(std::string(e.what()).find("view"), std::string::npos) << e.what();
  }
}

TEST(SideCalibrationDropsAView, AScreenViewThatDoesNotDecode) {
  Manifest manifest = LeftManifest();
  const std::filesystem::path noise = NoiseImage(manifest);
  manifest.screen_views[2].image = noise;
  const SideCalibration c = CalibrateSide(manifest);
  ASSERT_EQ(c.dropped_views.size(), 1u);
  const DroppedView* d = Dropped(c, ViewKind::kScreen, 2);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->image, noise);
  EXPECT_NE(d->reason.find("could not be decoded"), std::string::npos) << d->reason;
  ASSERT_EQ(c.screen_views.size(), manifest.screen_views.size() - 1);
  EXPECT_TRUE(Unused(c, noise, manifest.screen_views[2].z_mm));
  // Three screens at 0, 40, 120 mm still give the light planes and the
  // projector.
  EXPECT_LE(c.perspective.report.rms_mm, kMaxPlaneRmsMm);
  ASSERT_TRUE(c.projector_matrix.has_value());
  const geometry::PinholeModel projector =
      simulator::CalibrationProjector(Params(SessionKind::kLeftNoisy));
  EXPECT_LT((*c.projector.matrix_centre_mm - projector.Centre()).norm(), kProjectorCentreMm);
  const LightPlaneError off = LightPlanesOffTheTruth(SessionKind::kLeftNoisy, c);
  EXPECT_LT(off.perspective, kLightPlaneMm);
  EXPECT_LT(off.matrix, kLightPlaneMm);
  // Every used screen view has its residuals.
  for (const ScreenViewReport& v : c.screen_views) {
    EXPECT_GT(v.plane_rms_mm, 0.0) << v.image;
    ASSERT_TRUE(v.matrix_rms_d.has_value()) << v.image;
    EXPECT_GT(*v.matrix_rms_d, 0.0) << v.image;
    EXPECT_LT(*v.matrix_rms_d, 0.05) << v.image;  // d; the fit's own RMS is ~0.002 d
  }

  // The report names the dropped view and gives every used view's residual.
  const nlohmann::json report = CalibrationReport(c);
  ASSERT_EQ(report.at("dropped_views").size(), 1u);
  const nlohmann::json& dropped = report.at("dropped_views")[0];
  EXPECT_EQ(dropped.at("image"), noise.filename().string());
  EXPECT_EQ(dropped.at("kind"), "screen");
  EXPECT_EQ(dropped.at("index"), 2);
  EXPECT_EQ(dropped.at("z_mm").get<double>(), manifest.screen_views[2].z_mm);
  EXPECT_EQ(dropped.at("reason"), d->reason);
  EXPECT_EQ(report.at("camera").at("views").size(), c.camera_views.size());
  EXPECT_EQ(report.at("screens").size(), 3u);
  for (const nlohmann::json& v : report.at("screens"))
    EXPECT_TRUE(v.at("matrix_rms_d").is_number()) << v.dump();
  ASSERT_EQ(report.at("crosses").size(), c.reference_views.size());
  EXPECT_TRUE(report.at("crosses")[0].at("ray_residual_mm").is_number());

  // The calibration file keeps the dropped view: save, load, save is stable.
  const std::string yaml = CalibrationToYaml(c, "test");
  const CalibrationRecord loaded = CalibrationFromYaml(yaml, "test.yaml");
  ASSERT_EQ(loaded.calibration.dropped_views.size(), 1u);
  EXPECT_EQ(loaded.calibration.dropped_views[0].kind, ViewKind::kScreen);
  EXPECT_EQ(loaded.calibration.dropped_views[0].reason, d->reason);
  EXPECT_EQ(CalibrationToYaml(loaded.calibration, "test"), yaml);
}

TEST(SideCalibrationDropsAView, ACrossViewWithoutTheCross) {
  Manifest manifest = LeftManifest();
  manifest.reference_views[1].image = manifest.screen_views[0].image;  // bricks, no cross
  const SideCalibration c = CalibrateSide(manifest);
  ASSERT_EQ(c.dropped_views.size(), 1u);
  const DroppedView* d = Dropped(c, ViewKind::kReference, 1);
  ASSERT_NE(d, nullptr);
  EXPECT_NE(d->reason.find("reference cross not found"), std::string::npos) << d->reason;
  EXPECT_EQ(c.reference_views.size(), 2u);
  // Two crosses still fix every screen view's rows.
  const geometry::PinholeModel projector =
      simulator::CalibrationProjector(Params(SessionKind::kLeftNoisy));
  for (const ScreenViewReport& v : c.screen_views) EXPECT_TRUE(v.q_offset.has_value()) << v.image;
  ASSERT_TRUE(c.projector_matrix.has_value());
  EXPECT_NEAR(c.projector_matrix->model.intrinsics().cy, projector.intrinsics().cy, kSlideRowD);
  EXPECT_NEAR(c.projector_matrix->model.intrinsics().cx, projector.intrinsics().cx, kSlideRowD);
}

// With four crosses, the one off the line through the other three is told
// apart and dropped.
TEST(SideCalibrationDropsAView, AMisreadCrossAmongFour) {
  Manifest manifest = LeftManifest();
  const auto& params = Params(SessionKind::kLeftNoisy);
  const double extra_z = 30.0;
  const cv::Mat extra =
      simulator::Renderer(simulator::CalibrationScreenScene(Side::kLeft, extra_z, true, params),
                          params.render)
          .RenderImage(101);
  const std::filesystem::path path =
      std::filesystem::path(::testing::TempDir()) / "bsls_side_calibration_cross_z030.png";
  io::WritePngAtomically(path.string(), extra);
  ASSERT_EQ(manifest.reference_views.size(), 3u);  // 0, 60, 120 mm
  manifest.reference_views.insert(manifest.reference_views.begin() + 1, {path, extra_z});
  manifest.reference_views[2].z_mm += 10.0;  // the 60 mm cross, misreported
  const SideCalibration c = CalibrateSide(manifest);
  ASSERT_EQ(c.dropped_views.size(), 1u);
  const DroppedView* d = Dropped(c, ViewKind::kReference, 2);
  ASSERT_NE(d, nullptr) << c.dropped_views[0].index << ": " << c.dropped_views[0].reason;
  EXPECT_NE(d->reason.find("off the line through the other cross centres"), std::string::npos)
      << d->reason;
  ASSERT_EQ(c.reference_views.size(), 3u);
  for (const ReferenceViewReport& r : c.reference_views)
    EXPECT_LT(r.ray_residual_mm, kReferenceRayMm) << r.image;
  // The ray of the three left is the true ray of slide point (0, 0).
  const geometry::Ray truth = simulator::CalibrationProjector(params).BackProject({0.0, 0.0});
  ASSERT_TRUE(c.reference_ray.has_value());
  for (const double z : {0.0, 60.0, 120.0}) {
    const Eigen::Vector3d expected = truth.At((z - truth.origin.z()) / truth.direction.z());
    EXPECT_LT((*c.reference_ray->AtZ(z) - expected).norm(), kReferenceRayMm) << z;
  }
}

// Too few views of a kind left: refused, naming every dropped view and why.
TEST(SideCalibrationErrors, TooFewScreenViewsLeftNamesTheDroppedOnes) {
  Manifest manifest = LeftManifest();
  const std::filesystem::path noise = NoiseImage(manifest);
  manifest.screen_views[1].image = noise;
  manifest.screen_views[3].image = manifest.camera_views[0].image;  // the target, no bricks
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kNotFound);
  const std::string what = e.what();
  EXPECT_NE(what.find(manifest.path.string()), std::string::npos) << what;
  EXPECT_NE(what.find("2 of 4 screen views usable, at least 3 are needed"), std::string::npos)
      << what;
  EXPECT_NE(what.find(noise.string() + " (screen view 2, z = 40 mm): the brick pattern could "
                                       "not be decoded"),
            std::string::npos)
      << what;
  EXPECT_NE(what.find(manifest.camera_views[0].image.string() + " (screen view 4"),
            std::string::npos)
      << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
}

TEST(SideCalibrationErrors, TooFewCameraViewsLeftNamesTheDroppedOnes) {
  Manifest manifest = LeftManifest();
  for (int i = 0; i < 4; ++i) manifest.camera_views[i].image = manifest.screen_views[0].image;
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kNotFound);
  const std::string what = e.what();
  EXPECT_NE(what.find("2 of 6 camera views usable, at least 3 are needed"), std::string::npos)
      << what;
  for (int i = 1; i <= 4; ++i)
    EXPECT_NE(what.find("(camera view " + std::to_string(i) + ", z = "), std::string::npos) << what;
  EXPECT_NE(what.find("target not found"), std::string::npos) << what;
}

TEST(SideCalibrationErrors, TooFewCrossViewsLeftNamesTheDroppedOnes) {
  Manifest manifest = LeftManifest();
  manifest.reference_views[0].image = manifest.screen_views[0].image;
  manifest.reference_views[2].image = manifest.screen_views[0].image;
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kNotFound);
  const std::string what = e.what();
  EXPECT_NE(what.find("1 of 3 reference views usable, at least 2 are needed"), std::string::npos)
      << what;
  EXPECT_NE(what.find("(reference view 1, z = 0 mm): reference cross not found"), std::string::npos)
      << what;
  EXPECT_NE(what.find("(reference view 3, z = 120 mm): reference cross not found"),
            std::string::npos)
      << what;
}

}  // namespace
}  // namespace bsls::calibration

namespace bsls::calibration {
namespace {

// Both sessions place the target alike (the simulator's default), so the left
// and right calibrations share one world frame; moving one side's frame (as a
// target placed elsewhere would) breaks it, and so does a side twice.
TEST(SharesWorldFrame, SameTargetPlacementSharesAndAMovedFrameDoesNot) {
  const SideCalibration& left = testing::SessionCalibration(testing::SessionKind::kLeftNoisy);
  const SideCalibration& right = testing::SessionCalibration(testing::SessionKind::kRightClean);
  std::string why;
  EXPECT_TRUE(SharesWorldFrame(left, right, &why)) << why;
  EXPECT_FALSE(SharesWorldFrame(left, left, &why));
  EXPECT_NE(why.find("same side"), std::string::npos) << why;
  SideCalibration moved = right;
  const Eigen::Vector3d shift(20.0, 0.0, 0.0);  // mm
  *moved.projector.matrix_centre_mm += shift;
  moved.projector.plane_centre_mm += shift;
  EXPECT_FALSE(SharesWorldFrame(left, moved, &why));
  EXPECT_NE(why.find("projector centres"), std::string::npos) << why;
}

}  // namespace
}  // namespace bsls::calibration
