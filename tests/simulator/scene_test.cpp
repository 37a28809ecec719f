#include "bsls/simulator/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "bsls/simulator/ground_truth.h"
#include "test_options.h"

namespace bsls::simulator {
namespace {

using pattern::Side;

constexpr double kPixelTolerance = 1e-9;

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

TEST(SurfaceKind, NamesRoundTrip) {
  for (const SurfaceKind kind : {SurfaceKind::kPlane, SurfaceKind::kRamp, SurfaceKind::kBall,
                                 SurfaceKind::kFace, SurfaceKind::kBunny})
    EXPECT_EQ(ParseSurfaceKind(ToString(kind)), kind);
  EXPECT_FALSE(ParseSurfaceKind("sphere").has_value());
}

TEST(ThesisRig, ProjectedPitchOnTheBasePlaneIsAbout5Point7Mm) {
  const geometry::PinholeModel projector = MakeProjector(RigParams{});
  // Slide s grows towards world +x, t towards world -y.
  const auto st = projector.Project({-730.0 / 128.0, 730.0 / 128.0 * 3.0, 0.0});
  ASSERT_TRUE(st.has_value());
  EXPECT_NEAR(st->x(), -1.0, 1e-12);
  EXPECT_NEAR(st->y(), -3.0, 1e-12);
}

TEST(ThesisRig, RightCameraIsTheMirrorOfTheLeft) {
  const RigParams rig;
  const geometry::PinholeModel left = MakeCamera(rig, Side::kLeft);
  const geometry::PinholeModel right = MakeCamera(rig, Side::kRight);
  EXPECT_NEAR(right.Centre().x(), 240.0, 1e-9);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-80.0, 80.0);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d point(coord(rng), coord(rng), coord(rng) + 80.0);
    const auto a = left.Project(point);
    const auto b = right.Project({-point.x(), point.y(), point.z()});
    ASSERT_TRUE(a && b);
    EXPECT_NEAR(b->x(), rig.width - 1 - a->x(), kPixelTolerance);
    EXPECT_NEAR(b->y(), a->y(), kPixelTolerance);
  }
}

TEST(ThesisRig, RejectsInvalidFieldsByName) {
  RigParams rig;
  rig.width = 2;
  std::string error;
  EXPECT_FALSE(rig.IsValid(&error));
  EXPECT_NE(error.find("image size"), std::string::npos) << error;
  rig = RigParams{};
  rig.left_camera_target_mm = rig.left_camera_centre_mm + Eigen::Vector3d::UnitY();
  EXPECT_FALSE(rig.IsValid(&error));
  ThesisSceneOptions options = TestOptions();
  options.rig = rig;
  EXPECT_THROW(ThesisScene(Side::kLeft, SurfaceKind::kPlane, options), std::invalid_argument);
}

// The default face scene and its ground truth, computed once.
class ThesisFaceScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(ThesisScene(Side::kLeft, SurfaceKind::kFace, TestOptions()));
    truth_ = new GroundTruth(ComputeGroundTruth(*scene_));
  }
  static void TearDownTestSuite() {
    delete truth_;
    delete scene_;
  }
  static Scene* scene_;
  static GroundTruth* truth_;
};
Scene* ThesisFaceScene::scene_ = nullptr;
GroundTruth* ThesisFaceScene::truth_ = nullptr;

TEST_F(ThesisFaceScene, FaceFills85To90PercentOfTheImageHeight) {
  int top = -1, bottom = -1;
  for (int y = 0; y < scene_->height; ++y) {
    if (cv::countNonZero(truth_->maps.hit.row(y)) == 0) continue;
    if (top < 0) top = y;
    bottom = y;
  }
  const double fraction = (bottom - top + 1) / static_cast<double>(scene_->height);
  EXPECT_GE(fraction, 0.85);
  EXPECT_LE(fraction, 0.90);
}

TEST_F(ThesisFaceScene, HalfFaceCarriesLinesZeroToAboutFourteen) {
  ASSERT_FALSE(truth_->lines.empty());
  EXPECT_EQ(truth_->lines.front().p, 0);
  const int last = truth_->lines.back().p;
  EXPECT_GE(last, 12);
  EXPECT_LE(last, 16);
  // Every line from 0 to `last` is there.
  EXPECT_EQ(static_cast<int>(truth_->lines.size()), last + 1);
}

TEST_F(ThesisFaceScene, StripePitchIsTwelveToFifteenPixelsAndStripesAboutTwo) {
  // Pitch between neighbouring lines 4..11 on the rows around the image centre.
  std::vector<double> pitches;
  for (int row = scene_->height / 2 - 40; row <= scene_->height / 2 + 40; row += 10) {
    std::map<int, double> x_of_line;
    for (const TruthLine& line : truth_->lines)
      for (const Eigen::Vector2d& point : line.points)
        if (point.y() == row) x_of_line[line.p] = point.x();
    for (int p = 4; p < 11; ++p)
      if (x_of_line.count(p) && x_of_line.count(p + 1))
        pitches.push_back(x_of_line[p] - x_of_line[p + 1]);
  }
  ASSERT_GT(pitches.size(), 30u);
  const double pitch = Median(pitches);
  EXPECT_GE(pitch, 12.0);
  EXPECT_LE(pitch, 16.0);
  const double stripe = scene_->pattern.stroke_width * pitch;
  EXPECT_GE(stripe, 1.4);
  EXPECT_LE(stripe, 2.1);
}

TEST_F(ThesisFaceScene, LineZeroIsTheRightMostLitLineOnTheLeftImage) {
  std::map<int, double> line0_x;
  for (const Eigen::Vector2d& point : truth_->lines.front().points)
    line0_x[static_cast<int>(point.y())] =
        std::max(line0_x[static_cast<int>(point.y())], point.x());
  int rows_checked = 0;
  for (const TruthLine& line : truth_->lines) {
    if (line.p == 0) continue;
    for (const Eigen::Vector2d& point : line.points) {
      const auto it = line0_x.find(static_cast<int>(point.y()));
      if (it == line0_x.end()) continue;
      EXPECT_LT(point.x(), it->second) << "line " << line.p << " row " << point.y();
      ++rows_checked;
    }
  }
  EXPECT_GT(rows_checked, 1000);
}

TEST_F(ThesisFaceScene, PixelMapsAgreeWithTracingEachPixel) {
  // The projector sits in front of the face, so almost every seen pixel is lit
  // (the left slide's right half is dark slide, but lit); cast shadows are
  // tested on the resting ball below.
  const int hit = cv::countNonZero(truth_->maps.hit);
  const int lit = cv::countNonZero(truth_->maps.lit);
  EXPECT_GT(hit, scene_->width * scene_->height / 3);
  EXPECT_LE(lit, hit);
  // Every lit pixel centre re-traces as lit and reaches the projector.
  for (int y = 0; y < scene_->height; y += 17) {
    for (int x = 0; x < scene_->width; x += 13) {
      const auto sample = scene_->TraceCameraRay(scene_->camera.BackProject(Eigen::Vector2d(x, y)));
      ASSERT_EQ(sample.has_value(), truth_->maps.hit.at<uchar>(y, x) != 0);
      if (!sample) continue;
      EXPECT_EQ(sample->lit, truth_->maps.lit.at<uchar>(y, x) != 0);
      if (sample->lit) {
        EXPECT_TRUE(scene_->ProjectorReaches(sample->hit.point));
      }
    }
  }
}

TEST(ThesisBall, BallRestingOnThePlaneCastsAShadowTheCameraSees) {
  ThesisSceneOptions options = TestOptions();
  options.ball.centre_mm = {-70.0, 0.0, 40.0};  // resting on the base plane
  options.ball.radius_mm = 40.0;
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kBall, options);
  EXPECT_FALSE(scene.ProjectorReaches({-110.0, 0.0, 0.0}));  // under the ball's left limb
  EXPECT_TRUE(scene.ProjectorReaches({-5.0, 0.0, 0.0}));
  EXPECT_TRUE(scene.ProjectorReaches({-70.0, 0.0, 80.0}));  // top of the ball
  const GroundTruth truth = ComputeGroundTruth(scene);
  int shadowed = 0;
  for (int y = 0; y < scene.height; ++y) {
    for (int x = 0; x < scene.width; ++x) {
      if (!truth.maps.hit.at<uchar>(y, x) || truth.maps.lit.at<uchar>(y, x)) continue;
      if (std::abs(truth.maps.height.at<double>(y, x)) > 1e-6) continue;  // base plane only
      ++shadowed;
      const geometry::Ray ray = scene.camera.BackProject(Eigen::Vector2d(x, y));
      EXPECT_FALSE(scene.ProjectorReaches(ray.At(truth.maps.depth.at<double>(y, x))));
    }
  }
  EXPECT_GT(shadowed, 200);
  // Junctions never lie in the shadow; some lie right at its edge.
  int near_edge = 0;
  for (const TruthJunction& j : truth.junctions) {
    EXPECT_TRUE(scene.ProjectorReaches(j.world));
    if (j.visible && j.world.z() < 1e-6 && j.boundary_distance_px < 3.0) ++near_edge;
  }
  EXPECT_GT(near_edge, 0);
}

TEST(ThesisScenes, EveryKindBuildsForBothSides) {
  for (const SurfaceKind kind : {SurfaceKind::kPlane, SurfaceKind::kRamp, SurfaceKind::kBall,
                                 SurfaceKind::kFace, SurfaceKind::kBunny}) {
    for (const Side side : {Side::kLeft, Side::kRight}) {
      const Scene scene = ThesisScene(side, kind, TestOptions());
      std::string error;
      EXPECT_TRUE(scene.IsValid(&error)) << ToString(kind) << ": " << error;
      EXPECT_EQ(scene.slide, pattern::BrickSlideFor(side));
      // The camera looks at something in the middle of the image.
      const auto hit =
          scene.Intersect(scene.camera.BackProject({scene.width / 2.0, scene.height / 2.0}),
                          std::numeric_limits<double>::infinity());
      EXPECT_TRUE(hit.has_value()) << ToString(kind);
    }
  }
}

}  // namespace
}  // namespace bsls::simulator
