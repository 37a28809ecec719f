#include "bsls/extraction/feature_extraction.h"

#include <gtest/gtest.h>

#include <iostream>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "brick_scoring.h"
#include "expect_invalid.h"
#include "synthetic_images.h"

namespace bsls::extraction {
namespace {

using testing::BrickScene;
using testing::BrickTruth;
using testing::ExpectInvalid;
using testing::SkeletonScore;

// Junctions: a junction pixel within 1.5 px of nearly every true T-junction
// and within 2 px of every one. (Zhang-Suen bends the line one pixel towards
// the branch at some T's, which with a half-pixel offset of the true
// junction gives up to ~1.7 px.)
constexpr double kMinJunctionsNear = 0.98;      // fraction within 1.5 px
constexpr double kMinJunctionsNearDark = 0.95;  // ... in the dark patch
constexpr double kWorstJunction = 2.0;          // px, every junction
constexpr double kMinCoverage = 0.995;          // line rows with a skeleton pixel nearby
constexpr double kMinCoverageDark = 0.97;

TEST(FeatureExtraction, ModernChainFindsEveryJunctionAndMergesNoLines) {
  for (std::uint32_t seed : {1u, 2u}) {
    BrickScene scene;
    scene.seed = seed;
    scene.row_pitch = 13.3;  // segment rows at every sub-pixel phase
    BrickTruth truth;
    const cv::Mat grey = testing::RenderBrickScene(scene, &truth);
    const ExtractionResult r = ExtractFeatures(grey, {});
    const SkeletonScore s = testing::ScoreSkeleton(r.skeleton, truth);
    std::cout << "[ modern chain ] seed " << seed << ": " << s << "\n";
    EXPECT_TRUE(s.one_pixel_wide);
    EXPECT_GE(s.junctions_within_1_5, kMinJunctionsNear);
    EXPECT_GE(s.junctions_within_1_5_dark, kMinJunctionsNearDark);
    EXPECT_LE(s.worst_junction, kWorstJunction);
    EXPECT_GE(s.line_coverage, kMinCoverage);
    EXPECT_GE(s.line_coverage_dark, kMinCoverageDark);
    EXPECT_EQ(s.merges, 0);
    EXPECT_LE(s.false_junctions, 1);
  }
}

// With a second thread the re-centring's smoothing runs on it while the
// skeleton is thinned; with one thread it runs band by band afterwards. The
// mask and the skeleton are the same to the pixel either way.
TEST(FeatureExtraction, ModernChainDoesNotDependOnTheThreadCount) {
  const int threads = cv::getNumThreads();
  BrickScene scene;
  scene.seed = 3;
  const cv::Mat grey = testing::RenderBrickScene(scene, nullptr);
  cv::setNumThreads(1);
  const ExtractionResult one = ExtractFeatures(grey, {});
  cv::setNumThreads(2);  // a second thread even on a machine of one core
  const ExtractionResult two = ExtractFeatures(grey, {});
  cv::setNumThreads(threads);
  ASSERT_GT(cv::countNonZero(one.skeleton), 1000);
  EXPECT_EQ(cv::countNonZero(one.mask != two.mask), 0);
  EXPECT_EQ(cv::countNonZero(one.skeleton != two.skeleton), 0);
}

TEST(FeatureExtraction, ThesisChainOnThinStripes) {
  // The thesis chain (Canny marks both flanks, line following pairs them)
  // suits thin stripes; measured here, not required to match the modern one.
  BrickScene scene;
  scene.min_line_width = 1.0;
  scene.max_line_width = 2.0;
  scene.segment_width = 1.5;
  scene.dark_patch = false;
  BrickTruth truth;
  const cv::Mat grey = testing::RenderBrickScene(scene, &truth);
  ExtractionParams params;
  params.method = ExtractionMethod::kThesis;
  const ExtractionResult r = ExtractFeatures(grey, params);
  const SkeletonScore s = testing::ScoreSkeleton(r.skeleton, truth);
  std::cout << "[ thesis chain ] thin stripes: " << s << "\n";
  EXPECT_TRUE(s.one_pixel_wide);
  EXPECT_GE(s.line_coverage, 0.85);
}

TEST(FeatureExtraction, OutputsHaveTheInputSizeAndDocumentedTypes) {
  BrickScene scene;
  scene.width = 160;
  scene.height = 120;
  const cv::Mat grey = testing::RenderBrickScene(scene, nullptr);
  for (ExtractionMethod method : {ExtractionMethod::kModern, ExtractionMethod::kThesis}) {
    ExtractionParams params;
    params.method = method;
    const ExtractionResult r = ExtractFeatures(grey, params);
    for (const cv::Mat* m : {&r.mask, &r.skeleton}) {
      EXPECT_EQ(m->size(), grey.size());
      EXPECT_EQ(m->type(), CV_8UC1);
    }
    EXPECT_EQ(cv::countNonZero((r.skeleton != 0) & (r.skeleton != 255)), 0);
    if (method == ExtractionMethod::kModern) {
      EXPECT_TRUE(r.smoothed.empty());  // the modern chain does not smooth
    } else {
      EXPECT_EQ(r.smoothed.size(), grey.size());
      EXPECT_EQ(r.smoothed.type(), CV_8UC1);
      EXPECT_EQ(cv::countNonZero(r.smoothed != Enhance(grey, params.enhance)), 0);
    }
  }
}

TEST(FeatureExtraction, DegenerateFramesGiveEmptyOrTrivialSkeletons) {
  const std::vector<cv::Mat> frames = {
      cv::Mat(1, 1, CV_8UC1, cv::Scalar(0)),   cv::Mat(3, 3, CV_8UC1, cv::Scalar(255)),
      cv::Mat(1, 64, CV_8UC1, cv::Scalar(90)), cv::Mat(64, 1, CV_8UC1, cv::Scalar(90)),
      cv::Mat(64, 64, CV_8UC1, cv::Scalar(0)), cv::Mat(64, 64, CV_8UC1, cv::Scalar(255)),
  };
  for (ExtractionMethod method : {ExtractionMethod::kModern, ExtractionMethod::kThesis}) {
    ExtractionParams params;
    params.method = method;
    for (const cv::Mat& frame : frames) {
      const ExtractionResult r = ExtractFeatures(frame, params);
      EXPECT_EQ(r.skeleton.size(), frame.size());
      EXPECT_EQ(cv::countNonZero(r.skeleton), 0) << frame.size() << " " << frame.at<uchar>(0, 0);
    }
  }
}

TEST(FeatureExtraction, RandomFramesOfAnySizeAreHandled) {
  // Seeded random frames (noise, blobs and lines) of odd sizes through both
  // chains: outputs of the right shape, always one pixel wide.
  std::mt19937 rng(77);
  std::uniform_int_distribution<int> side(2, 90), coord(0, 89), grey(0, 255);
  for (int trial = 0; trial < 30; ++trial) {
    cv::Mat frame(side(rng), side(rng), CV_8UC1);
    cv::randu(frame, 0, 40 + trial * 7);
    for (int k = 0; k < 6; ++k)
      cv::line(frame, {coord(rng), coord(rng)}, {coord(rng), coord(rng)}, grey(rng), 1 + k % 4);
    for (ExtractionMethod method : {ExtractionMethod::kModern, ExtractionMethod::kThesis}) {
      ExtractionParams params;
      params.method = method;
      const ExtractionResult r = ExtractFeatures(frame, params);
      ASSERT_EQ(r.skeleton.size(), frame.size()) << trial;
      EXPECT_EQ(cv::countNonZero(MakeOnePixelWide(r.skeleton) != r.skeleton), 0) << trial;
    }
  }
}

TEST(FeatureExtraction, InvalidInputsGiveTheDocumentedError) {
  const cv::Mat empty;
  const cv::Mat colour(8, 8, CV_8UC3, cv::Scalar::all(1));
  const cv::Mat wide(8, 8, CV_16UC1, cv::Scalar(1));
  for (const cv::Mat* bad : {&empty, &colour, &wide})
    ExpectInvalid([&] { ExtractFeatures(*bad); }, "ExtractFeatures");
  ExtractionParams params;
  params.min_component_pixels = 0;
  std::string why;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("min_component_pixels"), std::string::npos);
  ExpectInvalid([&] { ExtractFeatures(cv::Mat(8, 8, CV_8UC1, cv::Scalar(0)), params); },
                "ExtractFeatures");
}

}  // namespace
}  // namespace bsls::extraction
