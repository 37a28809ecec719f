// MeasureStripePitch on synthetic combs of stripes with a known pitch.
#include "bsls/extraction/stripe_pitch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

namespace bsls::extraction {
namespace {

constexpr double kPitchTolerance = 0.02;  // fraction of the true pitch

// Bright vertical stripes (Gaussian profile of the given sigma, contrast 80
// on a ground of 20) every `pitch` px over the left `lit` fraction of the
// width, with horizontal bright segments every `pitch` rows (the brick's),
// and Gaussian noise of sigma 3.
cv::Mat Comb(int size, double pitch, double sigma, double lit, unsigned seed) {
  cv::Mat f(size, size, CV_32F, cv::Scalar(20));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size * lit; ++x) {
      const double dx = std::remainder(x - 3.3, pitch);
      const double dy = std::remainder(y - 1.7, pitch);
      f.at<float>(y, x) +=
          static_cast<float>(80.0 * std::max(std::exp(-0.5 * dx * dx / (sigma * sigma)),
                                             std::exp(-0.5 * dy * dy / (sigma * sigma))));
    }
  cv::Mat noise(f.size(), CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  cv::Mat out;
  cv::Mat(f + noise).convertTo(out, CV_8U);
  return out;
}

TEST(StripePitch, FindsThePitchOfACombAtEverySize) {
  for (double pitch : {7.0, 12.5, 15.0, 21.0, 50.0, 61.3}) {
    const cv::Mat frame = Comb(pitch > 30 ? 1024 : 512, pitch, 0.12 * pitch, 0.6, 1);
    const auto measured = MeasureStripePitch(frame);
    ASSERT_TRUE(measured.has_value()) << "pitch " << pitch;
    EXPECT_NEAR(*measured, pitch, kPitchTolerance * pitch);
  }
}

TEST(StripePitch, NoiseAndBlankFramesHaveNone) {
  cv::Mat noise(256, 256, CV_8U);
  cv::RNG(3).fill(noise, cv::RNG::NORMAL, 100.0, 3.0);
  EXPECT_FALSE(MeasureStripePitch(noise).has_value());
  EXPECT_FALSE(MeasureStripePitch(cv::Mat(256, 256, CV_8U, cv::Scalar(40))).has_value());
}

// Stripes whose spacing grows steadily across the frame, as on a surface
// seen at a slant (13 px at the left, 3.2 times that at the right; a stripe
// at x_k with x_{k+1} = x_k * r). The pitch reported is one the frame has
// (within its range, near the middle of the spacings), never a multiple.
TEST(StripePitch, AChangingPitchGivesOneOfItsOwn) {
  constexpr int kSize = 1024;
  cv::Mat f(kSize, kSize, CV_32F, cv::Scalar(20));
  std::vector<double> stripes;
  for (double x = 60.0, step = 13.0; x < kSize - 10; x += step, step *= 1.06) stripes.push_back(x);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (double s : stripes)
        if (std::abs(x - s) < 12.0)
          f.at<float>(y, x) += static_cast<float>(80.0 * std::exp(-0.5 * (x - s) * (x - s) / 4.0));
  cv::Mat noise(f.size(), CV_32F);
  cv::RNG(5).fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  cv::Mat frame;
  cv::Mat(f + noise).convertTo(frame, CV_8U);
  const auto measured = MeasureStripePitch(frame);
  ASSERT_TRUE(measured.has_value());
  const double first = stripes[1] - stripes[0], last = stripes.back() - stripes[stripes.size() - 2];
  EXPECT_GT(*measured, first);
  EXPECT_LT(*measured, last);
  // Within the middle half of the spacings (each appears once per row).
  std::vector<double> spacings;
  for (size_t k = 1; k < stripes.size(); ++k) spacings.push_back(stripes[k] - stripes[k - 1]);
  EXPECT_GE(*measured, spacings[spacings.size() / 4] / 1.15);
  EXPECT_LE(*measured, spacings[spacings.size() * 3 / 4] * 1.15);
}

// Every other stripe dark over most of the frame (a shadow or a dark
// albedo band takes one in two): the spacing that remains elsewhere is the
// pitch, not the doubled one, as long as it holds for a fair share of the
// frame.
TEST(StripePitch, StripesMissingInEveryOtherPlaceDoNotDoubleIt) {
  cv::Mat frame = Comb(512, 14.0, 0.12 * 14.0, 1.0, 2);
  for (int y = 0; y < frame.rows; ++y)
    for (int x = 0; x < frame.cols * 3 / 5; ++x)
      if (static_cast<int>(std::floor((x - 3.3 + 7.0) / 14.0)) % 2 == 0) frame.at<uchar>(y, x) = 20;
  const auto measured = MeasureStripePitch(frame);
  ASSERT_TRUE(measured.has_value());
  EXPECT_NEAR(*measured, 14.0, kPitchTolerance * 14.0);
}

TEST(StripePitch, InvalidInputIsRejected) {
  EXPECT_THROW(MeasureStripePitch(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(MeasureStripePitch(cv::Mat(64, 64, CV_32F, cv::Scalar(0))), std::invalid_argument);
  StripePitchParams bad;
  bad.central_band = 0.0;
  EXPECT_THROW(MeasureStripePitch(cv::Mat(64, 64, CV_8U, cv::Scalar(0)), bad),
               std::invalid_argument);
}

}  // namespace
}  // namespace bsls::extraction
