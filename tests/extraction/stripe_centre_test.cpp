#include "bsls/extraction/stripe_centre.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "expect_invalid.h"
#include "synthetic_images.h"

namespace bsls::extraction {
namespace {

using testing::ExpectInvalid;

// Accuracy target of the brief: noise sigma 3, contrast >= 60 grey levels.
constexpr double kRmsTarget = 0.1;          // px
constexpr double kNoiseFreeBias = 0.03;     // px, worst case without noise (8-bit rounding)
constexpr double kMinFoundFraction = 0.99;  // proper stripes must be found

constexpr double kPsf = 0.8;  // px, optical blur of the test stripes
constexpr double kBackground = 30.0;
constexpr double kContrast = 60.0;  // box height above the ground
constexpr double kNoise = 3.0;
constexpr double kSlope = 0.073;  // px per row: every sub-pixel phase occurs

struct Accuracy {
  double rms = 0.0;
  double worst = 0.0;
  double found = 0.0;  // fraction of rows with an answer
};

// Measures StripeCentreInRow (or, on the transposed image, ...InColumn)
// along a slanted stripe; the approximate position is off by up to 1.5 px.
Accuracy Measure(double width, double noise, bool columns, std::uint32_t seed) {
  const cv::Size size(64, 160);
  const double x0 = 28.3;
  cv::Mat image = testing::RenderSlantedStripe(size, x0, kSlope, width, kPsf, kBackground,
                                               kContrast, noise, seed);
  if (columns) image = image.t();
  std::mt19937 rng(seed + 1000);
  std::uniform_real_distribution<double> offset(-1.5, 1.5);
  double sum_sq = 0.0, worst = 0.0;
  int found = 0, total = 0;
  for (int i = 2; i < size.height - 2; ++i) {
    const double truth = x0 + kSlope * i;
    const double guess = truth + offset(rng);
    const auto c =
        columns ? StripeCentreInColumn(image, i, guess) : StripeCentreInRow(image, i, guess);
    ++total;
    if (!c) continue;
    ++found;
    const double e = *c - truth;
    sum_sq += e * e;
    worst = std::max(worst, std::abs(e));
  }
  return {std::sqrt(sum_sq / std::max(found, 1)), worst, static_cast<double>(found) / total};
}

TEST(StripeCentre, RmsErrorMeetsTheTargetForWidthsOneToTen) {
  for (double width : {1.0, 2.0, 3.0, 6.0, 10.0}) {
    const Accuracy a = Measure(width, kNoise, /*columns=*/false, 17);
    std::cout << "[ stripe centre ] width " << width << " px: RMS " << a.rms << " px, worst "
              << a.worst << " px, found " << a.found << "\n";
    EXPECT_LE(a.rms, kRmsTarget) << "width " << width;
    EXPECT_GE(a.found, kMinFoundFraction) << "width " << width;
  }
}

TEST(StripeCentre, ColumnVersionMeasuresHorizontalStripesAsWell) {
  for (double width : {1.0, 3.0, 10.0}) {
    const Accuracy a = Measure(width, kNoise, /*columns=*/true, 23);
    EXPECT_LE(a.rms, kRmsTarget) << "width " << width;
    EXPECT_GE(a.found, kMinFoundFraction) << "width " << width;
  }
}

// StripeCentreInRow / InColumn take from the image only the part of the
// profile their measurement reads; their answers are those of
// MeasureStripeProfile on the whole profile (averaged over 2 along_radius + 1
// rows with binomial weights), to the last bit: narrow and wide stripes, the
// approximate position off by up to 3 px, stripes near the image's edge.
TEST(StripeCentre, ImageMeasurementEqualsTheWholeProfiles) {
  StripeCentreParams params;
  const int reach = params.search_radius + 7 + 6 + 23 + 2;  // the widest stripe's reach
  int compared = 0;
  for (double width : {1.0, 3.0, 6.0, 10.0, 13.0}) {
    for (double x0 : {3.2, 28.3, 60.4}) {  // near the left edge, inside, near the right edge
      const cv::Mat image = testing::RenderSlantedStripe({64, 40}, x0, kSlope, width, kPsf,
                                                         kBackground, kContrast, kNoise, 5);
      const cv::Mat transposed = image.t();
      std::mt19937 rng(static_cast<std::uint32_t>(width * 100 + x0));
      std::uniform_real_distribution<double> offset(-3.0, 3.0);
      for (int y = 0; y < image.rows; ++y) {
        const double guess = std::clamp(x0 + kSlope * y + offset(rng), 0.0, 63.0);
        // The whole profile around the guess, as the image function would take it.
        const int centre = static_cast<int>(std::lround(guess));
        const int lo = std::max(0, centre - reach), hi = std::min(image.cols - 1, centre + reach);
        std::vector<double> profile(static_cast<size_t>(hi - lo + 1), 0.0);
        const double weights[3] = {0.25, 0.5, 0.25};
        double total = 0.0;
        for (int a = std::max(0, y - 1); a <= std::min(image.rows - 1, y + 1); ++a) {
          const double w = weights[a - y + 1];
          total += w;
          for (int x = lo; x <= hi; ++x) profile[x - lo] += w * image.at<uchar>(a, x);
        }
        if (total != 1.0)
          for (double& v : profile) v /= total;
        const auto whole = MeasureStripeProfile(profile, guess - lo, params);
        const auto in_row = StripeCentreInRow(image, y, guess, params);
        const auto in_column = StripeCentreInColumn(transposed, y, guess, params);
        ASSERT_EQ(whole.has_value(), in_row.has_value()) << width << " " << x0 << " " << y;
        ASSERT_EQ(in_row.has_value(), in_column.has_value());
        if (!whole) continue;
        EXPECT_EQ(whole->centre + lo, *in_row) << width << " " << x0 << " " << y;
        EXPECT_EQ(*in_row, *in_column);
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 300);
}

TEST(StripeCentre, NoPixelLockingWithoutNoise) {
  // Without noise only the method's own bias remains (8-bit rounding included).
  for (double width : {1.0, 2.0, 3.0, 6.0, 10.0}) {
    const Accuracy a = Measure(width, 0.0, false, 5);
    EXPECT_LE(a.worst, kNoiseFreeBias) << "width " << width;
  }
}

TEST(StripeCentre, NeighbouringStripesThirteenPixelsApartBarelyBias) {
  // A second stripe on one side only, 13 px away, widths up to 6 px.
  for (double width : {2.0, 4.0, 6.0}) {
    const auto a = testing::RenderStripeProfile(80, 30.4, width, kPsf, kBackground, kContrast);
    const auto b = testing::RenderStripeProfile(80, 43.4, width, kPsf, 0.0, kContrast);
    std::vector<double> both(a.size());
    for (size_t i = 0; i < a.size(); ++i) both[i] = a[i] + b[i];
    const auto m = MeasureStripeProfile(both, 30.0, {});
    ASSERT_TRUE(m.has_value()) << width;
    EXPECT_NEAR(m->centre, 30.4, 0.03) << width;
  }
}

// Stripes 4-6 px apart, as lines crowd where a fold turns the face away
// (thesis 5.1.4.8): measured one by one, each is pulled towards its
// neighbours by their light; fitted jointly, each comes out where it is.
// Three stripes 2 px wide (the simulated faces' lines), noise sigma 3,
// 100 rows each.
TEST(StripeCentre, CrowdedStripesFittedJointlyAreNotPulledByTheirNeighbours) {
  for (double gap : {4.0, 5.0, 6.0}) {
    const double truth[3] = {20.3, 20.3 + gap, 20.3 + 2.0 * gap - 0.4};
    std::vector<double> clean(48, kBackground);
    for (double c : truth) {
      const auto one = testing::RenderStripeProfile(48, c, 2.0, kPsf, 0.0, kContrast);
      for (size_t i = 0; i < clean.size(); ++i) clean[i] += one[i];
    }
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, kNoise);
    cv::Mat image(100, 48, CV_8UC1);
    for (int y = 0; y < image.rows; ++y)
      for (int x = 0; x < image.cols; ++x)
        image.at<uchar>(y, x) =
            cv::saturate_cast<uchar>(clean[static_cast<size_t>(x)] + noise(rng));
    double joint_sq = 0.0, single_sq = 0.0;
    int joint_found = 0, single_found = 0;
    for (int y = 0; y < image.rows; ++y) {
      // Approximate positions as a skeleton gives them: whole pixels.
      const std::vector<double> guess = {std::round(truth[0]), std::round(truth[1]),
                                         std::round(truth[2])};
      const auto joint = StripeCentresInRow(image, y, guess);
      ASSERT_EQ(joint.size(), 3u);
      for (int j = 0; j < 3; ++j) {
        if (joint[static_cast<size_t>(j)]) {
          ++joint_found;
          joint_sq += std::pow(*joint[static_cast<size_t>(j)] - truth[j], 2);
        }
        if (const auto one = StripeCentreInRow(image, y, guess[static_cast<size_t>(j)])) {
          ++single_found;
          single_sq += std::pow(*one - truth[j], 2);
        }
      }
    }
    const double joint_rms = std::sqrt(joint_sq / std::max(joint_found, 1));
    const double single_rms = std::sqrt(single_sq / std::max(single_found, 1));
    std::printf(
        "[ figures  ] gap %.0f px: joint fit %d of 300, RMS %.3f px; one by one %d, RMS %.3f px\n",
        gap, joint_found, joint_rms, single_found, single_rms);
    EXPECT_GE(joint_found, 297) << gap;
    EXPECT_LT(joint_rms, 0.15) << gap;
    // 6 px apart the stripes barely touch and one by one works as well.
    if (gap < 6.0) {
      EXPECT_LT(joint_rms, 0.5 * single_rms) << gap;
    }
  }
  // A single stripe: the joint fit of one is as good as the profile method.
  const cv::Mat one = testing::RenderSlantedStripe({48, 40}, 20.6, 0.0, 3.0, kPsf, kBackground,
                                                   kContrast, kNoise, 3);
  for (int y = 0; y < one.rows; ++y) {
    const double guess[1] = {21.0};
    const auto c = StripeCentresInRow(one, y, guess);
    ASSERT_TRUE(c[0].has_value()) << y;
    EXPECT_NEAR(*c[0], 20.6, 0.25) << y;
  }
}

// No stripe where the fit is asked for one: nothing comes back, and
// positions outside the image or out of order are refused.
TEST(StripeCentre, CrowdedFitAnswersOnlyForRealStripes) {
  cv::Mat flat(20, 40, CV_8UC1, cv::Scalar(30));
  const double guess[2] = {15.0, 20.0};
  for (const auto& c : StripeCentresInRow(flat, 5, guess)) EXPECT_FALSE(c.has_value());
  const double outside[2] = {-2.0, 5.0};
  for (const auto& c : StripeCentresInRow(flat, 5, outside)) EXPECT_FALSE(c.has_value());
  const double reversed[2] = {20.0, 15.0};
  ExpectInvalid([&] { StripeCentresInRow(flat, 5, reversed); }, "StripeCentresInRow");
  ExpectInvalid([&] { StripeCentresInRow(flat, 20, guess); }, "StripeCentresInRow");
  const double not_a_number[2] = {15.0, std::nan("")};
  ExpectInvalid([&] { StripeCentresInRow(flat, 5, not_a_number); }, "StripeCentresInRow");
  ExpectInvalid([&] { StripeCentresInRow(flat, 5, std::span<const double>()); },
                "StripeCentresInRow");
}

TEST(StripeCentre, ProfileMeasurementReportsWidthAndContrast) {
  const auto p = testing::RenderStripeProfile(60, 25.25, 6.0, kPsf, kBackground, kContrast);
  const auto m = MeasureStripeProfile(p, 26.0, {});
  ASSERT_TRUE(m.has_value());
  EXPECT_NEAR(m->centre, 25.25, 0.01);
  EXPECT_NEAR(m->width, 6.0, 1.0);
  EXPECT_NEAR(m->contrast, kContrast, 6.0);
}

TEST(StripeCentre, NoAnswerWhereThereIsNoRidge) {
  const StripeCentreParams params;
  // Flat.
  EXPECT_FALSE(MeasureStripeProfile(std::vector<double>(40, 50.0), 20.0, params).has_value());
  // A step edge.
  std::vector<double> step(40, 20.0);
  for (size_t i = 20; i < step.size(); ++i) step[i] = 140.0;
  EXPECT_FALSE(MeasureStripeProfile(step, 20.0, params).has_value());
  // A stripe whose peak lies outside the search radius.
  const auto far = testing::RenderStripeProfile(60, 35.0, 3.0, kPsf, kBackground, kContrast);
  EXPECT_FALSE(MeasureStripeProfile(far, 25.0, params).has_value());
  // Too weak.
  const auto weak = testing::RenderStripeProfile(60, 30.0, 3.0, kPsf, kBackground, 5.0);
  EXPECT_FALSE(MeasureStripeProfile(weak, 30.0, params).has_value());
  // Too wide to be a stripe (a bright plateau of 30 px).
  const auto plateau = testing::RenderStripeProfile(120, 60.0, 30.0, kPsf, kBackground, kContrast);
  EXPECT_FALSE(MeasureStripeProfile(plateau, 60.0, params).has_value());
  // Approximate position outside the image.
  const cv::Mat image = testing::RenderSlantedStripe({40, 10}, 20, 0, 3, kPsf, 30, 60, 0, 1);
  EXPECT_FALSE(StripeCentreInRow(image, 5, -3.0).has_value());
  EXPECT_FALSE(StripeCentreInRow(image, 5, 45.0).has_value());
}

TEST(StripeCentre, InvalidInputsGiveTheDocumentedError) {
  const cv::Mat empty;
  const cv::Mat colour(8, 8, CV_8UC3, cv::Scalar::all(1));
  const cv::Mat wide(8, 8, CV_16UC1, cv::Scalar(1));
  for (const cv::Mat* bad : {&empty, &colour, &wide}) {
    ExpectInvalid([&] { StripeCentreInRow(*bad, 2, 3.0); }, "StripeCentreInRow");
    ExpectInvalid([&] { StripeCentreInColumn(*bad, 2, 3.0); }, "StripeCentreInColumn");
  }
  const cv::Mat ok(8, 8, CV_8UC1, cv::Scalar(1));
  ExpectInvalid([&] { StripeCentreInRow(ok, 8, 3.0); }, "StripeCentreInRow");
  ExpectInvalid([&] { StripeCentreInColumn(ok, -1, 3.0); }, "StripeCentreInColumn");
  StripeCentreParams bad;
  bad.along_radius = 9;
  ExpectInvalid([&] { StripeCentreInRow(ok, 2, 3.0, bad); }, "StripeCentreInRow");
  // A float image is accepted.
  cv::Mat f;
  ok.convertTo(f, CV_32F);
  EXPECT_NO_THROW(StripeCentreInRow(f, 2, 3.0));
}

}  // namespace
}  // namespace bsls::extraction
