// MeasureStripePitch on synthetic combs of stripes with a known pitch.
#include "bsls/extraction/stripe_pitch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <stdexcept>

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
