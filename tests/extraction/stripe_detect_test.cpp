#include "bsls/extraction/stripe_detect.h"

#include <gtest/gtest.h>

#include <iostream>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "brick_scoring.h"
#include "bsls/extraction/feature_extraction.h"
#include "expect_invalid.h"
#include "synthetic_images.h"

namespace bsls::extraction {
namespace {

using testing::BrickScene;
using testing::BrickTruth;
using testing::ExpectInvalid;
using testing::MaskScore;
using testing::SkeletonScore;

// Targets for the default detector on the brick scenes.
constexpr double kMinRecall = 0.995;         // line-centre pixels in the mask
constexpr double kMinRecallDark = 0.97;      // ... in the dark patch (albedo 0.3)
constexpr double kMaxFalsePositive = 0.005;  // mask pixels > 2 px from every stroke

struct Comparison {
  MaskScore mask;
  SkeletonScore skeleton;
};

Comparison RunChain(StripeDetector detector, const BrickScene& scene) {
  BrickTruth truth;
  const cv::Mat grey = testing::RenderBrickScene(scene, &truth);
  ExtractionParams params;
  params.stripe.method = detector;
  const ExtractionResult r = ExtractFeatures(grey, params);
  return {testing::ScoreMask(r.mask, truth), testing::ScoreSkeleton(r.skeleton, truth)};
}

// The measurement behind the default (printed for the record): both
// detectors on brick scenes with widths 2-6 and 2-10 px, noise 3, a dark
// patch, through the same Zhang-Suen + pruning chain.
TEST(StripeDetect, DetectorComparison) {
  for (double max_width : {6.0, 10.0}) {
    BrickScene scene;
    scene.max_line_width = max_width;
    scene.seed = 3;
    const Comparison hessian = RunChain(StripeDetector::kHessianRidge, scene);
    const Comparison adaptive = RunChain(StripeDetector::kAdaptiveThreshold, scene);
    std::cout << "[ detectors ] widths 2-" << max_width << " px\n"
              << "  Hessian ridge mask:      " << hessian.mask << "\n"
              << "  Hessian ridge skeleton:  " << hessian.skeleton << "\n"
              << "  adaptive threshold mask: " << adaptive.mask << "\n"
              << "  adaptive skeleton:       " << adaptive.skeleton << "\n";
    EXPECT_GE(hessian.mask.recall, kMinRecall);
    EXPECT_GE(hessian.mask.recall_dark, kMinRecallDark);
    EXPECT_LE(hessian.mask.false_positive, kMaxFalsePositive);
    EXPECT_EQ(hessian.mask.bridges, 0);
    // The reason for the choice: the junctions of the dark patch (and, with
    // 10 px stripes, everywhere) survive.
    EXPECT_GE(hessian.skeleton.junctions_within_1_5, 0.98);
    EXPECT_GE(hessian.skeleton.junctions_within_1_5_dark, 0.85);
    EXPECT_GT(hessian.skeleton.junctions_within_1_5_dark,
              adaptive.skeleton.junctions_within_1_5_dark + 0.2);
  }
}

TEST(StripeDetect, MaskOfThinStripesIsTwoToFourPixelsWide) {
  for (double width : {1.0, 2.0, 3.0}) {
    const cv::Mat grey =
        testing::RenderSlantedStripe({48, 40}, 23.6, 0.0, width, 0.8, 25, 100, 3.0, 31);
    const cv::Mat mask = DetectStripes(grey, {});
    for (int y = 5; y < 35; ++y) {
      const int run = cv::countNonZero(mask.row(y));
      EXPECT_GE(run, 2) << "width " << width << " row " << y;
      EXPECT_LE(run, 4) << "width " << width << " row " << y;
      EXPECT_TRUE(mask.at<unsigned char>(y, 23) || mask.at<unsigned char>(y, 24)) << y;
    }
  }
}

TEST(StripeDetect, DoesNotBridgeNeighbouringStripesTenToTwelvePixelsApart) {
  for (double spacing : {10.0, 11.0, 12.0}) {
    for (double width : {2.0, 4.0, 6.0}) {
      const cv::Mat a =
          testing::RenderSlantedStripe({64, 40}, 24.3, 0.0, width, 0.8, 25, 100, 3.0, 41);
      const cv::Mat b =
          testing::RenderSlantedStripe({64, 40}, 24.3 + spacing, 0.0, width, 0.8, 0, 100, 0.0, 1);
      cv::Mat grey;
      cv::add(a, b, grey);
      const cv::Mat mask = DetectStripes(grey, {});
      for (int y = 5; y < 35; ++y) {
        const int gap = cv::countNonZero(mask.row(y).colRange(24, 25 + static_cast<int>(spacing)));
        EXPECT_LT(gap, static_cast<int>(spacing) + 1) << spacing << " " << width << " row " << y;
        EXPECT_TRUE(mask.at<unsigned char>(y, 24)) << spacing << " " << width << " row " << y;
      }
    }
  }
}

TEST(StripeDetect, KeepsTJunctionsConnected) {
  BrickScene scene;
  BrickTruth truth;
  const cv::Mat grey = testing::RenderBrickScene(scene, &truth);
  const cv::Mat mask = DetectStripes(grey, {});
  int inside = 0;
  for (const cv::Point2d& j : truth.junctions)
    inside += mask.at<unsigned char>(static_cast<int>(std::lround(j.y)),
                                     static_cast<int>(std::lround(j.x))) != 0;
  EXPECT_EQ(inside, static_cast<int>(truth.junctions.size()));
  // The whole pattern is one connected mask.
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
  int big = 0;
  for (int i = 1; i < n; ++i) big += stats.at<int>(i, cv::CC_STAT_AREA) > 1000;
  EXPECT_EQ(big, 1);
}

TEST(StripeDetect, RidgeStrengthReadsAboutTheContrast) {
  const cv::Mat grey = testing::RenderSlantedStripe({48, 40}, 24.0, 0.0, 4.0, 0.8, 20, 80, 0.0, 1);
  const cv::Mat r = RidgeStrength(grey, {});
  EXPECT_NEAR(r.at<float>(20, 24), 80.0, 20.0);
  EXPECT_LT(r.at<float>(20, 5), 1.0);
}

TEST(StripeDetect, InvalidInputsGiveTheDocumentedError) {
  const cv::Mat empty;
  const cv::Mat colour(8, 8, CV_8UC3, cv::Scalar::all(1));
  const cv::Mat wide(8, 8, CV_16UC1, cv::Scalar(1));
  for (const cv::Mat* bad : {&empty, &colour, &wide}) {
    ExpectInvalid([&] { DetectStripes(*bad, {}); }, "DetectStripes");
    ExpectInvalid([&] { RidgeStrength(*bad, {}); }, "RidgeStrength");
  }
  const cv::Mat ok(8, 8, CV_8UC1, cv::Scalar(0));
  StripeDetectParams bad;
  bad.contrast_window = 4;
  ExpectInvalid([&] { DetectStripes(ok, bad); }, "DetectStripes");
}

}  // namespace
}  // namespace bsls::extraction
