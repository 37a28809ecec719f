#include "bsls/calibration/reference_cross.h"

#include <gtest/gtest.h>

#include "bsls/simulator/renderer.h"
#include "bsls/simulator/scene.h"

namespace bsls::calibration {
namespace {

using pattern::Side;
using simulator::SurfaceKind;

constexpr double kCentreTolerancePx = 0.15;  // cross centre vs the rendered truth

cv::Mat RenderPlane(Side side, bool cross, double noise) {
  simulator::ThesisSceneOptions options;
  options.reference_cross = cross;
  simulator::RenderParams params;
  params.noise_sigma = noise;
  return simulator::Render(simulator::ThesisScene(side, SurfaceKind::kPlane, options), params)
      .image;
}

// Where slide point (u, v) = (0, 0) lands in the image of the base plane.
cv::Point2d TrueCentre(Side side) {
  const simulator::Scene scene = simulator::ThesisScene(side, SurfaceKind::kPlane, {});
  const geometry::Ray ray =
      scene.projector.BackProject(Eigen::Vector2d(pattern::SFromU(side, 0.0), 0.0));
  const Eigen::Vector3d on_plane = ray.At(-ray.origin.z() / ray.direction.z());
  const auto image = scene.camera.Project(on_plane);
  EXPECT_TRUE(image.has_value());
  return {image->x(), image->y()};
}

class CrossOnPlane : public ::testing::TestWithParam<Side> {};

TEST_P(CrossOnPlane, CentreFoundToSubPixel) {
  const Side side = GetParam();
  std::string why;
  const auto cross = FindReferenceCross(RenderPlane(side, true, 3.0), {}, &why);
  ASSERT_TRUE(cross.has_value()) << why;
  const cv::Point2d truth = TrueCentre(side);
  EXPECT_NEAR(cross->centre.x, truth.x, kCentreTolerancePx);
  EXPECT_NEAR(cross->centre.y, truth.y, kCentreTolerancePx);
  EXPECT_LT(cross->vertical_rms_px, 0.2);
  EXPECT_LT(cross->horizontal_rms_px, 0.2);
  EXPECT_GT(cross->vertical.size(), 100u);
  EXPECT_GT(cross->horizontal.size(), 100u);
}

TEST_P(CrossOnPlane, BrickSlideIsNotReadAsACross) {
  std::string why;
  EXPECT_FALSE(FindReferenceCross(RenderPlane(GetParam(), false, 3.0), {}, &why).has_value());
  EXPECT_FALSE(why.empty());
}

INSTANTIATE_TEST_SUITE_P(BothSides, CrossOnPlane, ::testing::Values(Side::kLeft, Side::kRight));

TEST(ReferenceCross, BlankFrameSaysWhy) {
  const cv::Mat blank(256, 256, CV_8UC1, cv::Scalar(40));
  std::string why;
  EXPECT_FALSE(FindReferenceCross(blank, {}, &why).has_value());
  EXPECT_NE(why.find("stroke"), std::string::npos) << why;
}

TEST(ReferenceCross, CutOffArmIsRefused) {
  cv::Mat frame = RenderPlane(Side::kLeft, true, 3.0);
  const cv::Point2d c = TrueCentre(Side::kLeft);
  frame.rowRange(cvRound(c.y) + 8, frame.rows).setTo(10);  // the lower arm is gone
  std::string why;
  EXPECT_FALSE(FindReferenceCross(frame, {}, &why).has_value());
  EXPECT_NE(why.find("short"), std::string::npos) << why;
}

TEST(ReferenceCross, InvalidInputThrows) {
  EXPECT_THROW(FindReferenceCross(cv::Mat(), {}, nullptr), std::invalid_argument);
  CrossParams bad;
  bad.max_rms_px = 0;
  EXPECT_THROW(FindReferenceCross(cv::Mat(64, 64, CV_8UC1), bad, nullptr), std::invalid_argument);
}

}  // namespace
}  // namespace bsls::calibration
