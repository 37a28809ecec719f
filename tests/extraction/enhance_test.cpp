#include "bsls/extraction/enhance.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "expect_invalid.h"

namespace bsls::extraction {
namespace {

using testing::ExpectInvalid;

constexpr double kKernelTolerance = 1e-6;

cv::Mat NoisyFlat(cv::Size size, double mean, double sigma, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(mean, sigma);
  cv::Mat out(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      out.at<unsigned char>(y, x) = cv::saturate_cast<unsigned char>(noise(rng));
  return out;
}

double StdDev(const cv::Mat& image) {
  cv::Scalar mean, sd;
  cv::meanStdDev(image, mean, sd);
  return sd[0];
}

TEST(Enhance, DaviesKernelSumsToOneAndHasTheDocumentedWeights) {
  const cv::Mat k = DaviesKernel();
  ASSERT_EQ(k.type(), CV_32FC1);
  ASSERT_EQ(k.size(), cv::Size(3, 3));
  EXPECT_NEAR(cv::sum(k)[0], 1.0, kKernelTolerance);
  const float expected[3][3] = {{3, 7, 3}, {7, 16, 7}, {3, 7, 3}};
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x)
      EXPECT_NEAR(k.at<float>(y, x) * 56.0f, expected[y][x], kKernelTolerance) << y << "," << x;
}

TEST(Enhance, BinomialKernelSumsToOne) {
  const cv::Mat k = BinomialKernel();
  EXPECT_NEAR(cv::sum(k)[0], 1.0, kKernelTolerance);
  EXPECT_NEAR(k.at<float>(1, 1) * 16.0f, 4.0f, kKernelTolerance);
  EXPECT_NEAR(k.at<float>(0, 0) * 16.0f, 1.0f, kKernelTolerance);
}

TEST(Enhance, DaviesSmoothIsTheWeightedMeanOfTheNeighbourhood) {
  const cv::Mat image = NoisyFlat({16, 16}, 100, 30, 3);
  const cv::Mat out = DaviesSmooth(image);
  const cv::Mat k = DaviesKernel();
  double expected = 0.0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      expected += k.at<float>(dy + 1, dx + 1) * image.at<unsigned char>(7 + dy, 9 + dx);
  EXPECT_NEAR(out.at<unsigned char>(7, 9), expected, 0.5 + 1e-6);
}

TEST(Enhance, IteratedBinomialApproximatesGaussianOfSigmaSqrtHalfN) {
  // The spread of an impulse after N passes has variance N / 2 per axis (eq. 4.5-4.6).
  for (int n : {1, 2, 4}) {
    cv::Mat impulse = cv::Mat::zeros(31, 31, CV_8UC1);
    impulse.at<unsigned char>(15, 15) = 255;
    const cv::Mat out = IteratedBinomialSmooth(impulse, n);
    double total = 0.0, second_moment = 0.0;
    for (int y = 0; y < out.rows; ++y)
      for (int x = 0; x < out.cols; ++x) {
        total += out.at<unsigned char>(y, x);
        second_moment += out.at<unsigned char>(y, x) * (x - 15.0) * (x - 15.0);
      }
    EXPECT_NEAR(second_moment / total, n / 2.0, 0.1 * n) << "N = " << n;
  }
}

TEST(Enhance, GaussianAndMedianReduceNoise) {
  const cv::Mat noisy = NoisyFlat({128, 128}, 100, 6, 11);
  EXPECT_LT(StdDev(GaussianSmooth(noisy, 1.0)), 0.5 * StdDev(noisy));
  EXPECT_LT(StdDev(MedianSmooth(noisy, 5)), 0.6 * StdDev(noisy));
}

TEST(Enhance, MedianRemovesImpulseNoise) {
  cv::Mat image(32, 32, CV_8UC1, cv::Scalar(50));
  image.at<unsigned char>(10, 10) = 255;
  image.at<unsigned char>(20, 5) = 0;
  const cv::Mat out = MedianSmooth(image, 3);
  EXPECT_EQ(out.at<unsigned char>(10, 10), 50);
  EXPECT_EQ(out.at<unsigned char>(20, 5), 50);
}

TEST(Enhance, AdaptiveContrastRaisesTheStdOfALowContrastRegion) {
  // Left half: strong texture; right half: the same texture at a tenth of the contrast.
  cv::Mat image(128, 128, CV_8UC1);
  std::mt19937 rng(9);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x)
      image.at<unsigned char>(y, x) =
          cv::saturate_cast<unsigned char>(100 + (x < 64 ? 30.0 : 3.0) * n(rng));
  AdaptiveContrastParams params;
  params.window = 7;
  params.k = 0.5;
  const cv::Mat out = AdaptiveContrast(image, params);
  const cv::Rect low(72, 8, 48, 112);
  EXPECT_GT(StdDev(out(low)), 2.0 * StdDev(image(low)));
  // The mean level is kept (eq. 4.2 adds the local mean back).
  EXPECT_NEAR(cv::mean(out(low))[0], cv::mean(image(low))[0], 3.0);
}

TEST(Enhance, AdaptiveContrastLeavesAFlatImageAlone) {
  const cv::Mat flat(40, 40, CV_8UC1, cv::Scalar(77));
  const cv::Mat out = AdaptiveContrast(flat, {});
  EXPECT_EQ(cv::countNonZero(out != flat), 0);
}

TEST(Enhance, HistogramEqualisationSpreadsTheGreyLevels) {
  const cv::Mat image = NoisyFlat({64, 64}, 100, 5, 2);
  double lo, hi;
  cv::minMaxLoc(HistogramEqualise(image), &lo, &hi);
  EXPECT_LT(lo, 10);
  EXPECT_GT(hi, 245);
}

TEST(Enhance, EnhanceAppliesTheChosenMethod) {
  const cv::Mat image = NoisyFlat({48, 48}, 90, 20, 4);
  EnhanceParams p;
  p.method = EnhanceMethod::kDavies;
  EXPECT_EQ(cv::countNonZero(Enhance(image, p) != DaviesSmooth(image)), 0);
  p.method = EnhanceMethod::kMedian;
  p.median_size = 5;
  EXPECT_EQ(cv::countNonZero(Enhance(image, p) != MedianSmooth(image, 5)), 0);
  p.method = EnhanceMethod::kNone;
  EXPECT_EQ(cv::countNonZero(Enhance(image, p) != image), 0);
}

TEST(Enhance, InvalidInputsGiveTheDocumentedError) {
  const cv::Mat empty;
  const cv::Mat colour(8, 8, CV_8UC3, cv::Scalar::all(1));
  const cv::Mat wide(8, 8, CV_16UC1, cv::Scalar(1));
  for (const cv::Mat* bad : {&empty, &colour, &wide}) {
    ExpectInvalid([&] { Enhance(*bad, {}); }, "Enhance");
    ExpectInvalid([&] { DaviesSmooth(*bad); }, "DaviesSmooth");
    ExpectInvalid([&] { GaussianSmooth(*bad, 1.0); }, "GaussianSmooth");
    ExpectInvalid([&] { AdaptiveContrast(*bad, {}); }, "AdaptiveContrast");
  }
  const cv::Mat ok(8, 8, CV_8UC1, cv::Scalar(1));
  ExpectInvalid([&] { GaussianSmooth(ok, 0.0); }, "GaussianSmooth");
  ExpectInvalid([&] { MedianSmooth(ok, 4); }, "MedianSmooth");
  ExpectInvalid([&] { IteratedBinomialSmooth(ok, 0); }, "IteratedBinomialSmooth");
  EnhanceParams p;
  p.method = EnhanceMethod::kAdaptiveContrast;
  p.adaptive.k = 1.5;
  std::string why;
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_FALSE(why.empty());
  ExpectInvalid([&] { Enhance(ok, p); }, "Enhance");
}

}  // namespace
}  // namespace bsls::extraction
