#include "bsls/extraction/edge_detect.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "expect_invalid.h"
#include "synthetic_images.h"

namespace bsls::extraction {
namespace {

using testing::ExpectInvalid;

// A histogram of `n` samples from two Gaussians (weights w1, 1 - w1).
std::vector<double> Bimodal(int bins, double mu1, double s1, double mu2, double s2, double w1,
                            int n, std::mt19937* rng) {
  std::vector<double> h(static_cast<size_t>(bins), 0.0);
  std::normal_distribution<double> a(mu1, s1), b(mu2, s2);
  std::uniform_real_distribution<double> pick(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    const double v = pick(*rng) < w1 ? a(*rng) : b(*rng);
    const int bin = static_cast<int>(std::floor(v));
    if (bin >= 0 && bin < bins) h[static_cast<size_t>(bin)] += 1.0;
  }
  return h;
}

TEST(TwoPeakThreshold, LiesBetweenThePeaksOfSeededBimodalData) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double mu1 = 20 + 40 * u(rng);
    const double mu2 = mu1 + 60 + 100 * u(rng);
    const double s1 = 4 + 6 * u(rng), s2 = 4 + 10 * u(rng);
    const double w1 = 0.2 + 0.7 * u(rng);  // either peak may be the higher
    const auto h = Bimodal(256, mu1, s1, mu2, s2, w1, 20000, &rng);
    const auto r = TwoPeakThreshold(h, {});
    ASSERT_TRUE(r.has_value()) << trial;
    EXPECT_LT(r->low_peak, r->threshold) << trial;
    EXPECT_LT(r->threshold, r->high_peak) << trial;
    // The peaks are found where the modes are, the threshold well clear of both.
    EXPECT_NEAR(r->low_peak, mu1, 2.0 + 0.5 * s1) << trial;
    EXPECT_NEAR(r->high_peak, mu2, 2.0 + 0.5 * s2) << trial;
    EXPECT_GT(r->threshold, mu1 + s1) << trial;
    EXPECT_LT(r->threshold, mu2 - s2) << trial;
  }
}

TEST(TwoPeakThreshold, NoAnswerWithoutTwoPeaks) {
  std::mt19937 rng(1);
  const auto unimodal = Bimodal(256, 100, 10, 100, 10, 0.5, 20000, &rng);
  EXPECT_FALSE(TwoPeakThreshold(unimodal, {}).has_value());
  EXPECT_FALSE(TwoPeakThreshold(std::vector<double>(256, 0.0), {}).has_value());
  EXPECT_FALSE(TwoPeakThreshold(std::vector<double>{}, {}).has_value());
  // A monotonically decaying tail has no second peak either.
  std::vector<double> decay(128);
  for (size_t i = 0; i < decay.size(); ++i) decay[i] = 1000.0 * std::exp(-0.05 * i);
  EXPECT_FALSE(TwoPeakThreshold(decay, {}).has_value());
}

TEST(TwoPeakThreshold, RejectsNegativeCountsAndBadParams) {
  ExpectInvalid([] { TwoPeakThreshold(std::vector<double>{1, -2, 3, 4}, {}); }, "TwoPeakThreshold");
  TwoPeakParams bad;
  bad.min_peak_separation = 1;
  ExpectInvalid([&] { TwoPeakThreshold(std::vector<double>(10, 1.0), bad); }, "TwoPeakThreshold");
}

TEST(TwoPeakThreshold, OfAnImageIsInImageUnits) {
  // Half the pixels near 30, half near 200 (a CV_32F image in arbitrary units).
  cv::Mat image(64, 64, CV_32F);
  std::mt19937 rng(3);
  std::normal_distribution<float> a(30, 5), b(200, 8);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) image.at<float>(y, x) = x < 32 ? a(rng) : b(rng);
  const auto t = TwoPeakThresholdOfImage(image, 128, {});
  ASSERT_TRUE(t.has_value());
  EXPECT_GT(*t, 60.0);
  EXPECT_LT(*t, 170.0);
}

TEST(HysteresisThreshold, KeepsWeakPixelsOnlyWhenConnectedToStrongOnes) {
  cv::Mat m = cv::Mat::zeros(10, 20, CV_32F);
  m.row(2).colRange(1, 10).setTo(0.5f);  // weak run with one strong pixel
  m.at<float>(2, 5) = 1.0f;
  m.row(6).colRange(1, 10).setTo(0.5f);  // weak run alone
  const cv::Mat out = HysteresisThreshold(m, 0.4, 0.9);
  EXPECT_EQ(cv::countNonZero(out.row(2)), 9);
  EXPECT_EQ(cv::countNonZero(out.row(6)), 0);
  ExpectInvalid([&] { HysteresisThreshold(m, 0.9, 0.4); }, "HysteresisThreshold");
}

TEST(Sobel, MagnitudeOfAStepIsFourTimesItsHeight) {
  cv::Mat step(16, 16, CV_8UC1, cv::Scalar(10));
  step.colRange(8, 16).setTo(60);
  const cv::Mat mag = SobelMagnitude(step);
  ASSERT_EQ(mag.type(), CV_32FC1);
  // |Gx| + |Gy| with the masks of eq. 4.12 at the step: 4 * 50 on each side of it.
  EXPECT_FLOAT_EQ(mag.at<float>(8, 7), 200.0f);
  EXPECT_FLOAT_EQ(mag.at<float>(8, 8), 200.0f);
  EXPECT_FLOAT_EQ(mag.at<float>(8, 3), 0.0f);
  const cv::Mat edges = SobelEdges(step, {});
  EXPECT_EQ(edges.at<unsigned char>(8, 7), 255);
  EXPECT_EQ(edges.at<unsigned char>(8, 2), 0);
}

TEST(Laplacian, MasksAreTheThesisOnesAndAnswerOnAStripeCentre) {
  const cv::Mat h1 = LaplacianKernel(LaplacianMask::kH1FourNeighbour);
  const cv::Mat h2 = LaplacianKernel(LaplacianMask::kH2EightNeighbour);
  EXPECT_FLOAT_EQ(h1.at<float>(1, 1), 4.0f);
  EXPECT_FLOAT_EQ(h1.at<float>(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(h2.at<float>(1, 1), 8.0f);
  EXPECT_FLOAT_EQ(h2.at<float>(0, 0), -1.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(cv::sum(h1)[0]), 0.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(cv::sum(h2)[0]), 0.0f);
  const cv::Mat stripe =
      testing::RenderSlantedStripe({48, 32}, 20.0, 0.0, 3.0, 0.8, 20, 120, 0.0, 1);
  const cv::Mat log = LaplacianOfGaussian(stripe, 1.0, LaplacianMask::kH2EightNeighbour);
  double best = -1e9;
  int best_x = -1;
  for (int x = 0; x < 48; ++x)
    if (log.at<float>(16, x) > best) {
      best = log.at<float>(16, x);
      best_x = x;
    }
  EXPECT_EQ(best_x, 20);
  LaplacianParams p;
  const cv::Mat edges = LaplacianEdges(stripe, p);
  EXPECT_EQ(edges.at<unsigned char>(16, 20), 255);
  EXPECT_EQ(edges.at<unsigned char>(16, 5), 0);
}

TEST(Canny, TwoPeakThresholdsMarkBothFlanksOfAStripe) {
  const cv::Mat stripe =
      testing::RenderSlantedStripe({64, 48}, 32.0, 0.0, 6.0, 0.8, 20, 120, 3.0, 7);
  CannyParams p;
  const CannyThresholds t = ChooseCannyThresholds(stripe, p);
  EXPECT_TRUE(t.from_two_peaks);
  EXPECT_NEAR(t.low, p.low_ratio * t.high, 1e-9);
  const cv::Mat edges = CannyEdges(stripe, p);
  ASSERT_EQ(edges.type(), CV_8UC1);
  // One response on each flank (x = 29, 35 +- 1) in most rows, none in the middle.
  int rows_with_both = 0;
  for (int y = 4; y < 44; ++y) {
    const bool left = cv::countNonZero(edges.row(y).colRange(27, 31)) > 0;
    const bool right = cv::countNonZero(edges.row(y).colRange(33, 38)) > 0;
    rows_with_both += left && right;
    EXPECT_EQ(edges.at<unsigned char>(y, 10), 0);
  }
  EXPECT_GE(rows_with_both, 36);
  // Fixed thresholds are used as given.
  p.automatic = false;
  p.high = 90;
  p.low = 30;
  const CannyThresholds fixed = ChooseCannyThresholds(stripe, p);
  EXPECT_EQ(fixed.high, 90);
  EXPECT_EQ(fixed.low, 30);
}

TEST(EdgeDetect, InvalidInputsGiveTheDocumentedError) {
  const cv::Mat empty;
  const cv::Mat colour(8, 8, CV_8UC3, cv::Scalar::all(1));
  const cv::Mat wide(8, 8, CV_16UC1, cv::Scalar(1));
  for (const cv::Mat* bad : {&empty, &colour, &wide}) {
    ExpectInvalid([&] { SobelMagnitude(*bad); }, "SobelMagnitude");
    ExpectInvalid([&] { CannyEdges(*bad, {}); }, "CannyEdges");
    ExpectInvalid([&] { LaplacianEdges(*bad, {}); }, "LaplacianEdges");
  }
  ExpectInvalid([&] { TwoPeakThresholdOfImage(empty, 64, {}); }, "TwoPeakThresholdOfImage");
  const cv::Mat ok(8, 8, CV_8UC1, cv::Scalar(1));
  CannyParams bad;
  bad.low_ratio = 0.0;
  ExpectInvalid([&] { CannyEdges(ok, bad); }, "CannyEdges");
}

}  // namespace
}  // namespace bsls::extraction
