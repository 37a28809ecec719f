// The simulated calibration session against target detection, the manifest
// reader and the decoder (thesis chapter 6). Camera views are rendered with
// sensor noise sigma 2 grey levels.
#include "bsls/simulator/calibration_session.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <ostream>
#include <string>

#include "bsls/calibration/manifest.h"
#include "bsls/calibration/target_detect.h"
#include "bsls/decoder/decoder.h"
#include "bsls/simulator/evaluation.h"
#include "bsls/simulator/ground_truth.h"

namespace bsls::pattern {
// "left" / "right" in test listings.
void PrintTo(Side side, std::ostream* os) { *os << ToString(side); }
}  // namespace bsls::pattern

namespace bsls::simulator {
namespace {

namespace fs = std::filesystem;
using pattern::Side;

constexpr double kNoiseSigma = 2.0;            // grey levels
constexpr double kCentreRmsTolerancePx = 0.1;  // detected vs true square centre, per side
constexpr double kCentreMaxTolerancePx = 0.3;  // worst square of a side
constexpr double kAlbedoTolerance = 1e-12;
constexpr double kProjectionTolerancePx = 1e-9;
constexpr double kJunctionReachPx = 2.5;  // decoded vs true junction
constexpr double kMinScreenRecall = 0.9;  // of the visible junctions

CalibrationSessionParams NoisyParams() {
  CalibrationSessionParams params;
  params.render.noise_sigma = kNoiseSigma;
  return params;
}

calibration::TargetGeometry Geometry(const CalibrationTargetParams& target) {
  calibration::TargetGeometry geometry;
  geometry.rows = target.rows;
  geometry.cols = target.cols;
  geometry.pitch_mm = target.pitch_mm;
  geometry.square_mm = target.square_mm;
  return geometry;
}

// One camera view rendered outside a session (no grid check).
cv::Mat RenderTargetView(Side side, double z_mm, const CalibrationSessionParams& params,
                         std::uint32_t seed) {
  return Renderer(CalibrationTargetScene(side, z_mm, params), TargetRenderParams(params))
      .RenderImage(seed);
}

std::string Name(Side side) { return std::string(pattern::ToString(side)); }

// "left" / "right" in parameterised test names.
std::string SideName(const ::testing::TestParamInfo<Side>& param) { return Name(param.param); }

TEST(CalibrationTarget, AlbedoPaintsSquaresWhereTheContractsPutThem) {
  CalibrationTargetParams target;
  target.ground_variation = 0.0;
  const AlbedoField albedo(TargetAlbedo(target));
  const double half = target.square_mm / 2.0;
  const double inner = half - target.edge_mm;  // clear of the soft edge
  for (const double z : {0.0, 70.0}) {
    for (int r = 0; r < target.rows; ++r) {
      for (int c = 0; c < target.cols; ++c) {
        const Eigen::Vector3d centre = TargetSquareCentre(target, r, c, z);
        EXPECT_EQ(centre, Eigen::Vector3d(c * target.pitch_mm, -r * target.pitch_mm, z));
        for (const double dx : {-inner, 0.0, inner})
          for (const double dy : {-inner, 0.0, inner})
            EXPECT_NEAR(albedo.At(centre + Eigen::Vector3d(dx, dy, 0.0)), target.square_albedo,
                        kAlbedoTolerance);
        // Half-way to the next square: white ground.
        const Eigen::Vector3d gap = centre + Eigen::Vector3d(target.pitch_mm / 2.0, 0.0, 0.0);
        EXPECT_NEAR(albedo.At(gap), target.ground_albedo, kAlbedoTolerance);
      }
    }
  }
  // The origin is the centre of square (0, 0); nothing lies above row 0 or
  // left of column 0.
  EXPECT_NEAR(albedo.At({0.0, target.pitch_mm, 0.0}), target.ground_albedo, kAlbedoTolerance);
  EXPECT_NEAR(albedo.At({-target.pitch_mm, 0.0, 0.0}), target.ground_albedo, kAlbedoTolerance);
}

TEST(CalibrationTarget, TrueCentresAreOrderedLikeTheImageForBothSides) {
  const CalibrationSessionParams params;
  for (const Side side : {Side::kLeft, Side::kRight}) {
    const geometry::PinholeModel camera = CalibrationCamera(params, side);
    const std::vector<Eigen::Vector2d> centres = TrueSquareCentres(camera, params.target, 40.0);
    ASSERT_EQ(centres.size(), 64u);
    for (int r = 0; r < 8; ++r) {
      for (int c = 0; c < 8; ++c) {
        const Eigen::Vector2d& p = centres[r * 8 + c];
        const auto expected = camera.Project(TargetSquareCentre(params.target, r, c, 40.0));
        ASSERT_TRUE(expected.has_value());
        EXPECT_LT((p - *expected).norm(), kProjectionTolerancePx);
        // Row 0 top and column 0 left in the image (contracts section 3).
        if (c > 0) {
          EXPECT_GT(p.x(), centres[r * 8 + c - 1].x()) << Name(side);
        }
        if (r > 0) {
          EXPECT_GT(p.y(), centres[(r - 1) * 8 + c].y()) << Name(side);
        }
      }
    }
  }
}

TEST(CalibrationSession, ViewNamesFollowTheContractsExample) {
  EXPECT_EQ(CalibrationViewName(CalibrationViewKind::kCamera, 0.0), "target_z000.png");
  EXPECT_EQ(CalibrationViewName(CalibrationViewKind::kScreen, 60.0), "screen_z060.png");
  EXPECT_EQ(CalibrationViewName(CalibrationViewKind::kReference, 120.0), "cross_z120.png");
  EXPECT_EQ(CalibrationViewName(CalibrationViewKind::kCamera, 12.5), "target_z12p5.png");
}

TEST(CalibrationSession, InvalidParamsNameTheField) {
  std::string why;
  CalibrationSessionParams params;
  EXPECT_TRUE(params.IsValid(&why)) << why;
  params.camera_z_mm = {0, 10, 10};
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("camera_z_mm lists 10 twice"), std::string::npos) << why;
  params = {};
  params.screen_z_mm = {-5};
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("screen_z_mm"), std::string::npos) << why;
  params = {};
  params.target.square_mm = params.target.pitch_mm;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("square_mm"), std::string::npos) << why;
  EXPECT_THROW(SimulateCalibrationSession(Side::kLeft, params), std::invalid_argument);
}

TEST(CalibrationSession, GridOutOfViewIsRefusedNamingViewAndSquare) {
  // The left camera loses the centred grid's left-most column above z = 125 mm.
  CalibrationSessionParams params;
  params.camera_z_mm = {0, 140};
  try {
    SimulateCalibrationSession(Side::kLeft, params);
    FAIL() << "a view with the grid out of the image was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("left camera view at z = 140 mm"), std::string::npos) << what;
    EXPECT_NE(what.find("square (row 0, col "), std::string::npos) << what;
  }
}

// Every camera view of the default session: the full grid, in order, each
// centre near the exact projection of its square's centre.
class SessionDetection : public ::testing::TestWithParam<Side> {};

TEST_P(SessionDetection, EveryCameraViewGivesTheFullGridAtSubPixelAccuracy) {
  const Side side = GetParam();
  CalibrationSessionParams params = NoisyParams();
  params.screen_z_mm.clear();
  params.reference_z_mm.clear();
  const CalibrationSession session = SimulateCalibrationSession(side, params);
  ASSERT_EQ(session.camera_views.size(), params.camera_z_mm.size());
  const calibration::TargetGeometry geometry = Geometry(params.target);
  double sum2 = 0.0, worst = 0.0;
  int count = 0;
  for (const CalibrationView& view : session.camera_views) {
    const calibration::TargetDetection detection = calibration::DetectTarget(view.image, geometry);
    ASSERT_TRUE(detection.ok) << Name(side) << " z = " << view.z_mm << ": " << detection.error;
    ASSERT_EQ(detection.squares.size(), view.square_centres.size());
    for (size_t i = 0; i < detection.squares.size(); ++i) {
      const calibration::TargetSquare& square = detection.squares[i];
      EXPECT_EQ(square.row * params.target.cols + square.col, static_cast<int>(i));
      const Eigen::Vector2d found(square.centre.x, square.centre.y);
      const double error = (found - view.square_centres[i]).norm();
      sum2 += error * error;
      worst = std::max(worst, error);
      ++count;
    }
  }
  const double rms = std::sqrt(sum2 / count);
  EXPECT_LT(rms, kCentreRmsTolerancePx) << Name(side);
  EXPECT_LT(worst, kCentreMaxTolerancePx) << Name(side);
  RecordProperty("centre_rms_px", std::to_string(rms));
  RecordProperty("centre_max_px", std::to_string(worst));
}

INSTANTIATE_TEST_SUITE_P(BothSides, SessionDetection, ::testing::Values(Side::kLeft, Side::kRight),
                         SideName);

TEST(CalibrationSession, TargetPartlyOutOfFrameGivesAClearError) {
  CalibrationSessionParams params = NoisyParams();
  params.grid_margin_px = -1.0;  // render it anyway
  const cv::Mat image = RenderTargetView(Side::kLeft, 140.0, params, 3);
  const calibration::TargetDetection detection =
      calibration::DetectTarget(image, Geometry(params.target));
  EXPECT_FALSE(detection.ok);
  EXPECT_TRUE(detection.squares.empty());
  EXPECT_NE(detection.error.find(" of 64 target squares"), std::string::npos) << detection.error;
}

TEST(CalibrationSession, PaintedOverSquareGivesAClearError) {
  const CalibrationSessionParams params = NoisyParams();
  const double z = 50.0;
  cv::Mat image = RenderTargetView(Side::kRight, z, params, 4);
  // Paint square (3, 4) and 0.5 mm around it with the paper's grey.
  const geometry::PinholeModel camera = CalibrationCamera(params, Side::kRight);
  const Eigen::Vector3d centre = TargetSquareCentre(params.target, 3, 4, z);
  const double half = params.target.square_mm / 2.0 + 0.5;
  std::vector<cv::Point> corners;
  for (const auto& [dx, dy] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const auto p = camera.Project(centre + Eigen::Vector3d(dx * half, dy * half, 0.0));
    ASSERT_TRUE(p.has_value());
    corners.emplace_back(static_cast<int>(std::lround(p->x())),
                         static_cast<int>(std::lround(p->y())));
  }
  const double paper = image.at<std::uint8_t>(20, 20);
  cv::fillConvexPoly(image, corners, cv::Scalar(paper));
  const calibration::TargetDetection detection =
      calibration::DetectTarget(image, Geometry(params.target));
  EXPECT_FALSE(detection.ok);
  EXPECT_NE(detection.error.find("found 63 of 64 target squares"), std::string::npos)
      << detection.error;
}

TEST(TargetPlacement, DefaultCentresTheGridUnderTheRig) {
  const CalibrationSessionParams params;
  const Eigen::Vector3d origin = TargetOriginInRig(params);
  const double half_width = 0.5 * (params.target.cols - 1) * params.target.pitch_mm;
  const double half_height = 0.5 * (params.target.rows - 1) * params.target.pitch_mm;
  EXPECT_EQ(origin, Eigen::Vector3d(-half_width, half_height, 0.0));
  // The grid's centre is the rig origin.
  const Eigen::Vector3d middle =
      TargetSquareCentre(params.target, params.target.rows - 1, params.target.cols - 1, 0.0) / 2.0;
  EXPECT_LT(CalibrationWorldToRig(params, middle).norm(), kProjectionTolerancePx);
}

TEST(TargetPlacement, WorldAndRigFramesDifferByTheOrigin) {
  CalibrationSessionParams params;
  params.target_origin_rig_mm = Eigen::Vector2d(-12.0, 30.0);
  const Eigen::Vector3d rig(5.0, -7.0, 42.0);
  const Eigen::Vector3d world = RigToCalibrationWorld(params, rig);
  EXPECT_EQ(world, Eigen::Vector3d(17.0, -37.0, 42.0));
  EXPECT_LT((CalibrationWorldToRig(params, world) - rig).norm(), 1e-12);
  // The same point seen by the rig camera and by the world-frame camera.
  for (const Side side : {Side::kLeft, Side::kRight}) {
    const auto a = MakeCamera(params.rig, side).Project(rig);
    const auto b = CalibrationCamera(params, side).Project(world);
    ASSERT_TRUE(a && b);
    EXPECT_LT((*a - *b).norm(), kProjectionTolerancePx);
  }
  EXPECT_LT((CalibrationProjector(params).Centre() -
             RigToCalibrationWorld(params, params.rig.projector_centre_mm))
                .norm(),
            1e-9);
  // (0, 0): the calibration world frame is the rig frame.
  params.target_origin_rig_mm = Eigen::Vector2d::Zero();
  EXPECT_EQ(RigToCalibrationWorld(params, rig), rig);
  params.target_origin_rig_mm = Eigen::Vector2d(std::nan(""), 0.0);
  std::string why;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("target_origin_rig_mm"), std::string::npos) << why;
}

TEST(TargetPlacement, RenderedSquaresLieWhereTheWorldCameraProjectsThem) {
  // The darkest pixel near the projection of a square's world centre is dark:
  // the albedo is placed in the rig frame, the truth given in the world frame.
  CalibrationSessionParams params;
  params.target_origin_rig_mm = Eigen::Vector2d(-30.0, 10.0);
  params.render.supersampling = 1;
  const double z = 20.0;
  const cv::Mat image = RenderTargetView(Side::kLeft, z, params, 1);
  const std::vector<Eigen::Vector2d> centres =
      TrueSquareCentres(CalibrationCamera(params, Side::kLeft), params.target, z);
  const double paper = image.at<std::uint8_t>(5, 5);
  for (const Eigen::Vector2d& c : centres) {
    const int x = static_cast<int>(std::lround(c.x()));
    const int y = static_cast<int>(std::lround(c.y()));
    ASSERT_TRUE(x >= 0 && y >= 0 && x < image.cols && y < image.rows);
    EXPECT_LT(image.at<std::uint8_t>(y, x), 0.3 * paper) << x << ", " << y;
  }
}

class SessionFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("calibration_session_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(SessionFolder, WrittenManifestLoadsAndListsEveryFile) {
  CalibrationSessionParams params = NoisyParams();
  params.camera_z_mm = {0, 50};
  params.screen_z_mm = {0, 60};
  params.reference_z_mm = {60};
  params.render.supersampling = 1;  // files and layout only
  const CalibrationSession session = SimulateCalibrationSession(Side::kRight, params);
  const fs::path manifest_path = WriteCalibrationSession(session, dir_ / "right");
  EXPECT_EQ(manifest_path, dir_ / "right" / kSessionManifestName);

  // The manifest text: the contracts' layout.
  std::ifstream text_file(manifest_path);
  const std::string text((std::istreambuf_iterator<char>(text_file)),
                         std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("side: right\n"), std::string::npos) << text;
  EXPECT_NE(text.find("target: {rows: 8, cols: 8, pitch_mm: 6.5, square_mm: 4}\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  - {image: target_z050.png, z_mm: 50}\n"), std::string::npos) << text;
  EXPECT_NE(text.find("pattern: {lines: 20, rows: 24}\n"), std::string::npos) << text;

  // The reader of processing/calibration accepts it (it checks every image exists).
  const calibration::Manifest manifest = calibration::LoadManifest(manifest_path);
  EXPECT_EQ(manifest.side, Side::kRight);
  EXPECT_EQ(manifest.target.rows, 8);
  EXPECT_EQ(manifest.target.cols, 8);
  EXPECT_DOUBLE_EQ(manifest.target.pitch_mm, 6.5);
  EXPECT_DOUBLE_EQ(manifest.target.square_mm, 4.0);
  EXPECT_EQ(manifest.pattern.lines, params.pattern.lines);
  EXPECT_EQ(manifest.pattern.rows, params.pattern.rows);
  auto expect_views = [&](const std::vector<calibration::ManifestView>& listed,
                          const std::vector<CalibrationView>& rendered) {
    ASSERT_EQ(listed.size(), rendered.size());
    for (size_t i = 0; i < listed.size(); ++i) {
      EXPECT_EQ(listed[i].image, dir_ / "right" / rendered[i].image_name);
      EXPECT_DOUBLE_EQ(listed[i].z_mm, rendered[i].z_mm);
      const cv::Mat read = cv::imread(listed[i].image.string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(read.empty()) << listed[i].image;
      EXPECT_EQ(read.type(), CV_8UC1);
      EXPECT_EQ(cv::norm(read, rendered[i].image, cv::NORM_INF), 0.0) << listed[i].image;
    }
  };
  expect_views(manifest.camera_views, session.camera_views);
  expect_views(manifest.screen_views, session.screen_views);
  expect_views(manifest.reference_views, session.reference_views);

  // Nothing else but the images, the manifest and the truth.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir_ / "right")) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 2 + 2 + 1 + 2);

  // The truth: devices and every square centre of every camera view.
  std::ifstream truth_file(dir_ / "right" / kSessionTruthName);
  const nlohmann::json truth = nlohmann::json::parse(truth_file);
  EXPECT_EQ(truth["side"], "right");
  EXPECT_DOUBLE_EQ(truth["camera"]["fx"].get<double>(), session.camera.intrinsics().fx);
  EXPECT_EQ(truth["projector"]["rotation"].size(), 9u);
  ASSERT_EQ(truth["camera_views"].size(), 2u);
  const nlohmann::json& view = truth["camera_views"][1];
  EXPECT_EQ(view["image"], "target_z050.png");
  ASSERT_EQ(view["squares"].size(), 64u);
  const nlohmann::json& square = view["squares"][8 * 3 + 5];
  EXPECT_EQ(square["row"], 3);
  EXPECT_EQ(square["col"], 5);
  EXPECT_DOUBLE_EQ(square["x"].get<double>(), session.camera_views[1].square_centres[29].x());
  EXPECT_DOUBLE_EQ(square["world"][0].get<double>(), 5 * 6.5);
  EXPECT_DOUBLE_EQ(square["world"][1].get<double>(), -3 * 6.5);
  EXPECT_DOUBLE_EQ(square["world"][2].get<double>(), 50.0);
  ASSERT_EQ(truth["target_origin_rig_mm"].size(), 3u);
  EXPECT_DOUBLE_EQ(truth["target_origin_rig_mm"][0].get<double>(), TargetOriginInRig(params).x());
  EXPECT_DOUBLE_EQ(truth["target_origin_rig_mm"][1].get<double>(), TargetOriginInRig(params).y());
  EXPECT_DOUBLE_EQ(truth["camera"]["translation"][1].get<double>(),
                   session.camera.pose().translation.y());
}

// Screen views: a plane, so the decoder labels its junctions (sanity check
// that the session's brick views can feed the projector calibration).
class ScreenView : public ::testing::TestWithParam<Side> {};

TEST_P(ScreenView, DecoderLabelsTheJunctions) {
  const Side side = GetParam();
  const CalibrationSessionParams params = NoisyParams();
  const Scene scene = CalibrationScreenScene(side, 60.0, false, params);
  const Frame frame = Renderer(scene, params.render).Render(5);
  const decoder::DecodeResult result = decoder::Decode(frame.image, side);
  ASSERT_TRUE(result.ok) << result.error;
  std::vector<PointLabel> decoded;
  for (const decoder::DecodedJunction& j : result.junctions)
    decoded.push_back({j.p, j.q, j.position});
  const LabelScore score = ScoreLabels(VisibleJunctions(frame.truth), decoded, kJunctionReachPx);
  EXPECT_GT(score.Recall(), kMinScreenRecall) << score.Summary();
  EXPECT_EQ(score.wrong_p, 0) << score.Summary();
  RecordProperty("junctions", score.Summary());
}

INSTANTIATE_TEST_SUITE_P(BothSides, ScreenView, ::testing::Values(Side::kLeft, Side::kRight),
                         SideName);

}  // namespace
}  // namespace bsls::simulator
