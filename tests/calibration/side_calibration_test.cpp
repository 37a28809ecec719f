// CalibrateSide on simulated sessions against the simulator's truth (thesis
// chapter 6; acceptance figures of the calibration issue on the thesis rig,
// Tables 2.1 / 2.2), and its errors on bad sessions.
#include "bsls/calibration/side_calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

#include "bsls/calibration/projector_calibration.h"
#include "bsls/simulator/calibration_session.h"
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

TEST_P(SimulatedSession, LightPlanesMatchTheTrueProjector) {
  const SessionKind kind = GetParam();
  const Side side = testing::SideOf(kind);
  const SideCalibration& c = testing::SessionCalibration(kind);
  const geometry::PinholeModel projector = simulator::CalibrationProjector(Params(kind));
  ASSERT_TRUE(c.projector_matrix.has_value());
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
        ASSERT_LT(std::abs(truth.SignedDistance(p)), 1e-6);
        worst_perspective = std::max(worst_perspective, std::abs(perspective.SignedDistance(p)));
        worst_matrix = std::max(worst_matrix, std::abs(matrix.SignedDistance(p)));
      }
    }
  }
  EXPECT_LT(worst_perspective, kLightPlaneMm);
  EXPECT_LT(worst_matrix, kLightPlaneMm);
  std::cout << "[ figures  ] " << Name(kind) << ": light planes off the truth by at most "
            << worst_perspective << " mm (perspective model), " << worst_matrix
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
  manifest.screen_views.resize(1);
  e = FailureOf(manifest);
  EXPECT_NE(std::string(e.what()).find("1 screen views; at least 2"), std::string::npos)
      << e.what();
}

TEST(SideCalibrationErrors, TargetNotFoundFailsTheWholeCalibrationNamingTheView) {
  Manifest manifest = LeftManifest();
  manifest.camera_views[3].image = manifest.screen_views[0].image;  // bricks, no target
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kNotFound);
  const std::string what = e.what();
  EXPECT_NE(what.find(manifest.screen_views[0].image.string() + " (camera view 4"),
            std::string::npos)
      << what;
  EXPECT_NE(what.find("target not found"), std::string::npos) << what;
}

TEST(SideCalibrationErrors, UndecodableScreenView) {
  Manifest manifest = LeftManifest();
  manifest.screen_views[2].image = manifest.camera_views[0].image;  // the target, no bricks
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kNotFound);
  EXPECT_NE(std::string(e.what()).find("(screen view 3"), std::string::npos) << e.what();
}

TEST(SideCalibrationErrors, CrossNotFound) {
  Manifest manifest = LeftManifest();
  manifest.reference_views[1].image = manifest.screen_views[0].image;  // bricks, no cross
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kNotFound);
  EXPECT_NE(std::string(e.what()).find("reference cross not found"), std::string::npos) << e.what();
}

TEST(SideCalibrationErrors, MisreportedCrossDepth) {
  Manifest manifest = LeftManifest();
  manifest.reference_views[1].z_mm += 10.0;  // the cross centre leaves the projector ray
  const CalibrationError e = FailureOf(manifest);
  EXPECT_EQ(e.reason(), CalibrationErrorReason::kInvalidInput);
  EXPECT_NE(std::string(e.what()).find("off the line through the other cross centres"),
            std::string::npos)
      << e.what();
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
