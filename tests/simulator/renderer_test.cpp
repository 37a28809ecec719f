#include "bsls/simulator/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>

#include "test_options.h"

namespace bsls::simulator {
namespace {

using pattern::Side;

constexpr double kReprojectionTolerancePx = 1e-9;
constexpr double kSlideTolerance = 1e-9;         // d
constexpr double kLineMaximumTolerancePx = 0.3;  // truth line point vs intensity peak
constexpr double kBrightFraction = 0.6;          // junction grey vs local maximum
constexpr double kNoiseSigmaTolerance = 0.05;    // relative

RenderParams NoiselessParams() {
  RenderParams params;
  params.noise_sigma = 0.0;
  params.supersampling = 2;
  return params;
}

// Sub-pixel position of the intensity maximum of `row` near x (log-parabola
// through the brightest pixel within +-2 px and its neighbours).
double PeakNear(const cv::Mat& grey, int y, double x) {
  const float* row = grey.ptr<float>(y);
  int best = static_cast<int>(std::lround(x));
  for (int k = -2; k <= 2; ++k)
    if (row[static_cast<int>(std::lround(x)) + k] > row[best])
      best = static_cast<int>(std::lround(x)) + k;
  const double a = std::log(row[best - 1]);
  const double b = std::log(row[best]);
  const double c = std::log(row[best + 1]);
  return best + 0.5 * (a - c) / (a - 2.0 * b + c);
}

// Pattern v at the nearest pixel centre (NaN when unlit).
double VAt(const GroundTruth& truth, const Eigen::Vector2d& point) {
  return truth.maps.v.at<double>(static_cast<int>(point.y()),
                                 static_cast<int>(std::lround(point.x())));
}

TEST(Renderer, PlaneJunctionsReprojectExactly) {
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, TestOptions());
  const GroundTruth truth = ComputeGroundTruth(scene);
  ASSERT_EQ(truth.junctions.size(), pattern::AllJunctions(scene.pattern).size());
  int visible = 0;
  for (const TruthJunction& j : truth.junctions) {
    EXPECT_NEAR(j.world.z(), 0.0, 1e-9);
    const auto image = scene.camera.Project(j.world);
    ASSERT_TRUE(image.has_value());
    EXPECT_NEAR(image->x(), j.image.x(), kReprojectionTolerancePx);
    EXPECT_NEAR(image->y(), j.image.y(), kReprojectionTolerancePx);
    const auto st = scene.projector.Project(j.world);
    ASSERT_TRUE(st.has_value());
    EXPECT_NEAR(st->x(), pattern::SFromU(Side::kLeft, j.p), kSlideTolerance);
    EXPECT_NEAR(st->y(), j.v, kSlideTolerance);
    // On a plane nothing hides anything: visible exactly when in the image
    // with no stroke cut by its edge.
    EXPECT_EQ(j.visible, j.in_image && !j.cut_by_edge) << j.p << "," << j.v;
    visible += j.visible ? 1 : 0;
  }
  EXPECT_GT(visible, 500);
}

TEST(Renderer, PlaneJunctionsLieOnBrightPixels) {
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, TestOptions());
  const Frame frame = Render(scene, NoiselessParams());
  int checked = 0;
  for (const TruthJunction& j : frame.truth.junctions) {
    if (!j.visible) continue;
    const int x = static_cast<int>(std::lround(j.image.x()));
    const int y = static_cast<int>(std::lround(j.image.y()));
    if (x < 5 || y < 5 || x >= scene.width - 5 || y >= scene.height - 5) continue;
    double local_max = 0.0;
    cv::minMaxLoc(frame.image(cv::Rect(x - 5, y - 5, 11, 11)), nullptr, &local_max);
    EXPECT_GE(frame.image.at<uchar>(y, x), kBrightFraction * local_max)
        << "junction " << j.p << "," << j.v << " at " << j.image.transpose();
    ++checked;
  }
  EXPECT_GT(checked, 500);
}

TEST(Renderer, PlaneLinePointsLieOnIntensityMaxima) {
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, TestOptions());
  RenderParams params = NoiselessParams();
  params.projector_blur_sigma_d = 0.03;
  params.camera_blur_sigma_px = 0.3;
  const Renderer renderer(scene, params);
  const cv::Mat grey = renderer.RenderNoiseless();
  const GroundTruth truth = ComputeGroundTruth(scene);
  int checked = 0;
  for (const TruthLine& line : truth.lines) {
    for (const Eigen::Vector2d& point : line.points) {
      if (point.x() < 4 || point.x() > scene.width - 5) continue;
      const double v = VAt(truth, point);
      if (std::abs(v - std::round(v)) < 0.3) continue;  // near a horizontal segment
      EXPECT_NEAR(PeakNear(grey, static_cast<int>(point.y()), point.x()), point.x(),
                  kLineMaximumTolerancePx)
          << "line " << line.p << " row " << point.y();
      ++checked;
    }
  }
  EXPECT_GT(checked, 3000);
}

TEST(Renderer, PlaneLinesHaveOnePointPerRowAndGrowTowardsSmallerX) {
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, TestOptions());
  const GroundTruth truth = ComputeGroundTruth(scene);
  ASSERT_EQ(static_cast<int>(truth.lines.size()), scene.pattern.lines);
  for (const TruthLine& line : truth.lines) {
    ASSERT_GT(line.points.size(), 100u);
    for (size_t i = 1; i < line.points.size(); ++i)
      EXPECT_EQ(line.points[i].y(), line.points[i - 1].y() + 1.0) << "line " << line.p;
  }
  // At the image centre row, x decreases with p on the left side.
  const int row = scene.height / 2;
  double previous = std::numeric_limits<double>::infinity();
  for (const TruthLine& line : truth.lines) {
    for (const Eigen::Vector2d& point : line.points) {
      if (point.y() != row) continue;
      EXPECT_LT(point.x(), previous) << "line " << line.p;
      previous = point.x();
    }
  }
}

TEST(Renderer, LeftAndRightPlaneScenesAreMirrorImages) {
  ThesisSceneOptions options = TestOptions();
  options.albedo.variation = 0.0;  // the albedo waves are not symmetric
  const Scene left = ThesisScene(Side::kLeft, SurfaceKind::kPlane, options);
  const Scene right = ThesisScene(Side::kRight, SurfaceKind::kPlane, options);
  const GroundTruth truth_left = ComputeGroundTruth(left);
  const GroundTruth truth_right = ComputeGroundTruth(right);
  ASSERT_EQ(truth_left.junctions.size(), truth_right.junctions.size());
  for (size_t i = 0; i < truth_left.junctions.size(); ++i) {
    const TruthJunction& a = truth_left.junctions[i];
    const TruthJunction& b = truth_right.junctions[i];
    ASSERT_EQ(a.p, b.p);
    ASSERT_EQ(a.v, b.v);
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.visible, b.visible);
    EXPECT_NEAR(b.image.x(), left.width - 1 - a.image.x(), kReprojectionTolerancePx);
    EXPECT_NEAR(b.image.y(), a.image.y(), kReprojectionTolerancePx);
    EXPECT_NEAR(b.world.x(), -a.world.x(), 1e-9);
  }
  // The images too: the slide rasters are exact mirrors.
  const RenderParams params = NoiselessParams();
  cv::Mat grey_left = Renderer(left, params).RenderNoiseless();
  cv::Mat grey_right = Renderer(right, params).RenderNoiseless();
  cv::Mat mirrored;
  cv::flip(grey_right, mirrored, 1);
  cv::Mat diff;
  cv::absdiff(grey_left, mirrored, diff);
  double max_diff = 0.0;
  cv::minMaxLoc(diff, nullptr, &max_diff);
  EXPECT_LT(max_diff, 1e-3);
}

TEST(Renderer, BallHidesJunctionsBehindItFromTheCamera) {
  // A ball standing high above the base plane (cut 15 mm below its equator),
  // not the default low cap, so that it hides part of the plane.
  ThesisSceneOptions options = TestOptions();
  options.ball.centre_mm = {-70.0, 0.0, -15.0};
  options.ball.radius_mm = 60.0;
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kBall, options);
  const GroundTruth truth = ComputeGroundTruth(scene);
  int hidden_on_base = 0;
  for (const TruthJunction& j : truth.junctions) {
    if (!j.in_image) continue;
    const auto seen =
        scene.Intersect(scene.camera.BackProject(j.image), std::numeric_limits<double>::infinity());
    ASSERT_TRUE(seen.has_value());
    const bool same_point = (seen->point - j.world).norm() < 1e-3;
    if (j.visible) {
      EXPECT_TRUE(same_point);
      EXPECT_GT(j.cos_view, 0.0);
    } else if (j.world.z() < 1e-6 && seen->point.z() > 1.0) {
      // On the base plane, behind the ball as the camera sees it.
      ++hidden_on_base;
      EXPECT_LT(seen->distance, (j.world - scene.camera.Centre()).norm());
      EXPECT_LT(j.boundary_distance_px, 32.0);
    }
  }
  EXPECT_GT(hidden_on_base, 3);
  // Line 0 passes beside the ball and stays visible; line 2 is hidden at v = 0.
  for (const TruthJunction& j : truth.junctions) {
    if (j.p == 0 && j.v == 0) {
      EXPECT_TRUE(j.visible);
    }
    if (j.p == 2 && j.v == 0) {
      EXPECT_FALSE(j.visible);
    }
  }
}

TEST(Renderer, FaceVisibilityFlagsAgreeWithThePixelMaps) {
  Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kFace, TestOptions());
  // Default set-up: the left camera sees the whole lit half of the face.
  const GroundTruth own = ComputeGroundTruth(scene);
  // The right camera looking at the left slide: the nose hides part of its left flank.
  scene.camera = MakeCamera(RigParams{}, Side::kRight);
  const GroundTruth crossed = ComputeGroundTruth(scene);
  // Shading normals (cos_view) may differ slightly from the facets' (visibility).
  constexpr double kShadingSlack = 0.05;
  struct Case {
    const GroundTruth* truth;
    int min_visible;
    int min_hidden;
    int max_hidden;
  };
  for (const Case& c : {Case{&own, 300, 0, 10}, Case{&crossed, 150, 20, 1000}}) {
    const GroundTruth& truth = *c.truth;
    int visible = 0, hidden_in_image = 0;
    for (const TruthJunction& j : truth.junctions) {
      EXPECT_TRUE(scene.ProjectorReaches(j.world));  // junctions are lit by construction
      if (!j.in_image) continue;
      const int x = static_cast<int>(std::lround(j.image.x()));
      const int y = static_cast<int>(std::lround(j.image.y()));
      const double depth = truth.maps.depth.at<double>(y, x);
      const double distance = (j.world - truth.camera.Centre()).norm();
      if (j.visible) {
        ++visible;
        EXPECT_GT(j.cos_view, -kShadingSlack);
        if (j.boundary_distance_px < 2.0) continue;
        // The pixel centre nearest to a visible junction sees the same line, lit.
        EXPECT_NE(truth.maps.lit.at<uchar>(y, x), 0);
        EXPECT_NEAR(truth.maps.u.at<double>(y, x), j.p, 0.5);
        EXPECT_NEAR(truth.maps.v.at<double>(y, x), j.v, 0.5);
        EXPECT_NEAR(depth, distance, 2.0);
      } else {
        ++hidden_in_image;
        // Hidden: something nearer covers it, or it faces away from the camera.
        EXPECT_TRUE(depth < distance - 1.0 || j.cos_view < kShadingSlack) << j.p << "," << j.v;
      }
    }
    EXPECT_GT(visible, c.min_visible);
    EXPECT_GE(hidden_in_image, c.min_hidden);
    EXPECT_LE(hidden_in_image, c.max_hidden);
  }
}

TEST(Renderer, FaceLinePointsMostlyLieOnIntensityMaxima) {
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kFace, TestOptions());
  RenderParams params = NoiselessParams();
  params.projector_blur_sigma_d = 0.03;
  params.camera_blur_sigma_px = 0.3;
  const cv::Mat grey = Renderer(scene, params).RenderNoiseless();
  const GroundTruth truth = ComputeGroundTruth(scene);
  std::vector<double> errors;
  for (const TruthLine& line : truth.lines) {
    for (const Eigen::Vector2d& point : line.points) {
      if (point.x() < 4 || point.x() > scene.width - 5) continue;
      const double v = VAt(truth, point);
      if (std::isnan(v) || std::abs(v - std::round(v)) < 0.3) continue;
      errors.push_back(
          std::abs(PeakNear(grey, static_cast<int>(point.y()), point.x()) - point.x()));
    }
  }
  ASSERT_GT(errors.size(), 1500u);
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.1);
  EXPECT_LT(errors[errors.size() * 9 / 10], kLineMaximumTolerancePx);
}

// Shot noise: variance noise_sigma^2 + shot_noise * (grey - black_level),
// checked on dark (ground) and bright (stripe) pixels apart.
TEST(Renderer, ShotNoiseGrowsWithTheSignal) {
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, TestOptions());
  RenderParams params;
  params.supersampling = 1;
  params.noise_sigma = 1.0;
  params.shot_noise = 0.5;
  const Renderer renderer(scene, params);
  const cv::Mat clean = renderer.RenderNoiseless();
  const cv::Mat noisy = renderer.RenderImage(23);
  // Variance over pixels whose clean grey lies in [lo, hi), against the model's.
  auto measured_over_model = [&](float lo, float hi) {
    double sum2 = 0.0, model = 0.0;
    int count = 0;
    for (int y = 0; y < clean.rows; ++y)
      for (int x = 0; x < clean.cols; ++x) {
        const float c = clean.at<float>(y, x);
        if (c < lo || c >= hi) continue;
        const double d = noisy.at<uchar>(y, x) - c;
        sum2 += d * d;
        model += 1.0 + 0.5 * std::max(0.0, c - params.black_level) + 1.0 / 12.0;
        ++count;
      }
    EXPECT_GT(count, 1000) << lo << ".." << hi;
    return count ? sum2 / model : 0.0;
  };
  EXPECT_NEAR(measured_over_model(6.0f, 40.0f), 1.0, 0.08);
  EXPECT_NEAR(measured_over_model(120.0f, 200.0f), 1.0, 0.08);
}

TEST(Renderer, NoiseHasTheRequestedStandardDeviation) {
  ThesisSceneOptions options = TestOptions();
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, options);
  RenderParams params;
  params.supersampling = 1;
  params.noise_sigma = 3.0;
  const Renderer renderer(scene, params);
  const cv::Mat clean = renderer.RenderNoiseless();
  const cv::Mat noisy = renderer.RenderImage(17);
  double sum = 0.0, sum2 = 0.0;
  int count = 0;
  for (int y = 0; y < clean.rows; ++y) {
    for (int x = 0; x < clean.cols; ++x) {
      const float c = clean.at<float>(y, x);
      if (c < 12.0f || c > 240.0f) continue;  // 4 sigma away from clamping
      const double d = noisy.at<uchar>(y, x) - c;
      sum += d;
      sum2 += d * d;
      ++count;
    }
  }
  ASSERT_GT(count, 100000);
  const double mean = sum / count;
  // Rounding to integers adds a uniform error of variance 1/12.
  const double sigma = std::sqrt(sum2 / count - mean * mean - 1.0 / 12.0);
  EXPECT_NEAR(mean, 0.0, 0.05);
  EXPECT_NEAR(sigma, params.noise_sigma, kNoiseSigmaTolerance * params.noise_sigma);
}

TEST(Renderer, SameSeedSameImageOtherSeedOtherImage) {
  const Scene scene = ThesisScene(Side::kRight, SurfaceKind::kRamp, TestOptions());
  RenderParams params;
  params.supersampling = 1;
  const Renderer renderer(scene, params);
  const cv::Mat a = renderer.RenderImage(5);
  const cv::Mat b = renderer.RenderImage(5);
  const cv::Mat c = renderer.RenderImage(6);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0);
  // A fresh renderer of an equal scene gives the same frame.
  const Frame again =
      Renderer(ThesisScene(Side::kRight, SurfaceKind::kRamp, TestOptions()), params).Render(5);
  EXPECT_EQ(cv::norm(a, again.image, cv::NORM_INF), 0.0);
}

TEST(Renderer, BrightestStripesReachAbout200To230Grey) {
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, TestOptions());
  const Frame frame = Render(scene, NoiselessParams());
  double max_grey = 0.0;
  cv::minMaxLoc(frame.image, nullptr, &max_grey);
  EXPECT_GE(max_grey, 200.0);
  EXPECT_LE(max_grey, 235.0);
  // Background of a face scene (no base plane) is the black level.
  const Scene face = ThesisScene(Side::kLeft, SurfaceKind::kFace, TestOptions());
  RenderParams params = NoiselessParams();
  params.supersampling = 1;
  const cv::Mat image = Renderer(face, params).RenderImage(1);
  EXPECT_NEAR(image.at<uchar>(2, 2), params.black_level, 0.5);
}

TEST(Renderer, DepthOfFieldBlursPlanesAwayFromFocus) {
  Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, TestOptions());
  scene.surfaces = {std::make_shared<PlaneSurface>(PlaneSurface::Horizontal(150.0))};
  RenderParams sharp = NoiselessParams();
  sharp.supersampling = 1;
  RenderParams defocused = sharp;
  defocused.projector_aperture_mm = 10.0;  // 150 mm before focus: sigma about 0.1 d
  double sharp_max = 0.0, defocused_max = 0.0;
  cv::minMaxLoc(Renderer(scene, sharp).RenderNoiseless(), nullptr, &sharp_max);
  cv::minMaxLoc(Renderer(scene, defocused).RenderNoiseless(), nullptr, &defocused_max);
  EXPECT_LT(defocused_max, 0.8 * sharp_max);
  // In the focus plane the aperture changes nothing.
  scene.surfaces = {std::make_shared<PlaneSurface>(PlaneSurface::Horizontal(0.0))};
  const cv::Mat a = Renderer(scene, sharp).RenderNoiseless();
  const cv::Mat b = Renderer(scene, defocused).RenderNoiseless();
  EXPECT_LT(cv::norm(a, b, cv::NORM_INF), 1e-3);
}

TEST(Renderer, ReferenceCrossHasOnlyLineZero) {
  ThesisSceneOptions options = TestOptions();
  const GroundTruth brick =
      ComputeGroundTruth(ThesisScene(Side::kLeft, SurfaceKind::kFace, options));
  options.reference_cross = true;
  const Scene cross_scene = ThesisScene(Side::kLeft, SurfaceKind::kFace, options);
  EXPECT_EQ(cross_scene.slide, pattern::Slide::kReferenceCross);
  const GroundTruth cross = ComputeGroundTruth(cross_scene);
  EXPECT_TRUE(cross.junctions.empty());
  ASSERT_EQ(cross.lines.size(), 1u);
  EXPECT_EQ(cross.lines[0].p, 0);
  // Same geometry, same centre line as the brick slide's line 0.
  ASSERT_EQ(cross.lines[0].points.size(), brick.lines[0].points.size());
  for (size_t i = 0; i < cross.lines[0].points.size(); ++i)
    EXPECT_EQ(cross.lines[0].points[i], brick.lines[0].points[i]);
}

TEST(Renderer, JsonCarriesTheTruthFields) {
  const Scene scene = ThesisScene(Side::kRight, SurfaceKind::kBall, TestOptions());
  const GroundTruth truth = ComputeGroundTruth(scene);
  const nlohmann::json json = ToJson(truth);
  EXPECT_EQ(json["side"], "right");
  EXPECT_EQ(json["slide"], 3);
  EXPECT_EQ(json["width"], 512);
  int visible = 0;
  for (const TruthJunction& j : truth.junctions) visible += j.visible ? 1 : 0;
  ASSERT_EQ(json["junctions"].size(), static_cast<size_t>(visible));
  EXPECT_EQ(json["junctions"].size() + json["hidden_junctions"].size(), truth.junctions.size());
  const nlohmann::json& first = json["junctions"][0];
  for (const char* key : {"x", "y", "p", "v", "kind", "world", "boundary_distance_px", "albedo"})
    EXPECT_TRUE(first.contains(key)) << key;
  EXPECT_EQ(first["world"].size(), 3u);
  EXPECT_EQ(json["lines"].size(), truth.lines.size());
  EXPECT_EQ(json["lines"][0]["points"][0].size(), 2u);
  EXPECT_EQ(json["camera"]["rotation"].size(), 9u);
}

TEST(Renderer, RejectsInvalidParamsByName) {
  RenderParams params;
  params.supersampling = 0;
  std::string error;
  EXPECT_FALSE(params.IsValid(&error));
  EXPECT_NE(error.find("supersampling"), std::string::npos) << error;
  const Scene scene = ThesisScene(Side::kLeft, SurfaceKind::kPlane, TestOptions());
  try {
    Renderer renderer(scene, params);
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("supersampling"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bsls::simulator
