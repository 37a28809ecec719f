#include "bsls/extraction/thinning.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

#include "bsls/extraction/feature_extraction.h"
#include "expect_invalid.h"
#include "synthetic_images.h"

namespace bsls::extraction {
namespace {

using testing::BinaryBar;
using testing::CountComponents;
using testing::Degree;
using testing::ExpectInvalid;

constexpr double kCentreTolerance = 0.5;  // px, from the true stripe centre
constexpr int kMaxSpur = 2;               // px

// Checks a thinned vertical stripe centred on x = centre over rows
// [body_top, body_bottom]: one pixel per row within kCentreTolerance, one
// component, and no branch longer than kMaxSpur anywhere.
void ExpectThinVerticalLine(const cv::Mat& skeleton, double centre, int body_top, int body_bottom,
                            const std::string& what) {
  EXPECT_EQ(CountComponents(skeleton), 1) << what;
  for (int y = body_top; y <= body_bottom; ++y) {
    std::vector<int> xs;
    for (int x = 0; x < skeleton.cols; ++x)
      if (skeleton.at<unsigned char>(y, x)) xs.push_back(x);
    ASSERT_EQ(xs.size(), 1u) << what << " row " << y;
    EXPECT_LE(std::abs(xs[0] - centre), kCentreTolerance) << what << " row " << y;
  }
  // Spurs: a pixel with 3+ neighbours would start a branch; every branch
  // from an end point must reach the line within kMaxSpur pixels.
  int ends = 0, junctions = 0;
  for (int y = 0; y < skeleton.rows; ++y)
    for (int x = 0; x < skeleton.cols; ++x) {
      if (!skeleton.at<unsigned char>(y, x)) continue;
      const int d = Degree(skeleton, x, y);
      ends += d == 1;
      junctions += d >= 3;
    }
  EXPECT_EQ(ends, 2) << what;
  EXPECT_EQ(junctions, 0) << what;
}

TEST(ZhangSuen, ThinsBarsOfWidthOneToTenToTheirCentreLine) {
  for (int w = 1; w <= 10; ++w) {
    const cv::Mat bar = BinaryBar({40, 60}, 12, w, 5, 54);
    const cv::Mat skeleton = MakeOnePixelWide(ZhangSuenThin(bar));
    // The body, clear of the ends where the skeleton bends into a corner.
    ExpectThinVerticalLine(skeleton, 12 + (w - 1) / 2.0, 5 + w, 54 - w,
                           "Zhang-Suen width " + std::to_string(w));
  }
}

TEST(LineFollowing, ThinsBarsOfWidthOneToTenToTheirCentreLine) {
  for (int w = 1; w <= 10; ++w) {
    const cv::Mat bar = BinaryBar({40, 60}, 12, w, 5, 54);
    const cv::Mat skeleton = MakeOnePixelWide(LineFollowingThin(bar, {}));
    ExpectThinVerticalLine(skeleton, 12 + (w - 1) / 2.0, 5, 54,
                           "line following width " + std::to_string(w));
  }
}

TEST(ModernChain, ThinsGreyStripesOfWidthOneToTenToTheirCentreLine) {
  // Grey stripes with blur and noise through the stripe detector, Zhang-Suen and pruning.
  for (int w = 1; w <= 10; ++w) {
    const double centre = 30.0 + 0.37 * w;  // various sub-pixel phases
    const cv::Mat grey =
        testing::RenderSlantedStripe({64, 80}, centre, 0.0, w, 0.8, 25, 120, 3.0, 100 + w);
    const ExtractionResult r = ExtractFeatures(grey, {});
    // Away from the image borders, where the stripe ends.
    ExpectThinVerticalLine(r.skeleton, centre, 12, 67, "modern chain width " + std::to_string(w));
  }
}

// Random blobs: unions of ellipses and rectangles, some touching.
cv::Mat RandomBlobs(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pos(8, 120), size(2, 14), kind(0, 2);
  std::uniform_real_distribution<double> angle(0, 180);
  cv::Mat img = cv::Mat::zeros(128, 128, CV_8UC1);
  for (int i = 0; i < 12; ++i) {
    const cv::Point c(pos(rng), pos(rng));
    switch (kind(rng)) {
      case 0:
        cv::ellipse(img, c, cv::Size(size(rng), size(rng)), angle(rng), 0, 360, 255, cv::FILLED);
        break;
      case 1:
        cv::rectangle(img, cv::Rect(c, cv::Size(size(rng), size(rng))), 255, cv::FILLED);
        break;
      default:  // a thick stroke
        cv::line(img, c, cv::Point(pos(rng), pos(rng)), 255, 1 + size(rng) / 4);
    }
  }
  return img;
}

TEST(ZhangSuen, KeepsTheNumberOfComponentsOfRandomBlobs) {
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    const cv::Mat blobs = RandomBlobs(seed);
    const cv::Mat skeleton = ZhangSuenThin(blobs);
    EXPECT_EQ(CountComponents(skeleton), CountComponents(blobs)) << "seed " << seed;
    EXPECT_EQ(CountComponents(MakeOnePixelWide(skeleton)), CountComponents(blobs)) << seed;
    // Thin: another pass changes nothing, and little is left.
    EXPECT_EQ(cv::countNonZero(ZhangSuenThin(skeleton) != skeleton), 0) << "seed " << seed;
    EXPECT_LT(cv::countNonZero(skeleton), cv::countNonZero(blobs) / 3) << "seed " << seed;
  }
}

TEST(ZhangSuen, TopologyGuardKeepsWhatTheClassicRuleErases) {
  // Eq. 4.18-4.20 in parallel delete a 2x2 square entirely.
  cv::Mat square = cv::Mat::zeros(8, 8, CV_8UC1);
  square(cv::Rect(3, 3, 2, 2)).setTo(255);
  ZhangSuenParams classic;
  classic.preserve_topology = false;
  EXPECT_EQ(cv::countNonZero(ZhangSuenThin(square, classic)), 0);
  EXPECT_EQ(CountComponents(ZhangSuenThin(square)), 1);
  // The thesis conditions themselves: a 3-wide bar loses its east and west
  // columns (step 1 removes south-east boundary points, step 2 north-west).
  const cv::Mat bar = BinaryBar({9, 12}, 3, 3, 0, 11);
  const cv::Mat thin = ZhangSuenThin(bar, classic);
  EXPECT_EQ(cv::countNonZero(thin.col(3)), 0);
  EXPECT_EQ(cv::countNonZero(thin.col(5)), 0);
  EXPECT_GT(cv::countNonZero(thin.col(4)), 8);
}

// Degrees of all set pixels.
std::vector<int> Degrees(const cv::Mat& skeleton) {
  std::vector<int> out;
  for (int y = 0; y < skeleton.rows; ++y)
    for (int x = 0; x < skeleton.cols; ++x)
      if (skeleton.at<unsigned char>(y, x)) out.push_back(Degree(skeleton, x, y));
  return out;
}

TEST(MakeOnePixelWide, RemovesStaircaseCorners) {
  cv::Mat stairs = cv::Mat::zeros(12, 12, CV_8UC1);
  // A 4-connected staircase: (1,1) (2,1) (2,2) (3,2) (3,3) ...
  for (int i = 1; i < 9; ++i) {
    stairs.at<unsigned char>(i, i) = 255;
    stairs.at<unsigned char>(i, i + 1) = 255;
  }
  const cv::Mat thin = MakeOnePixelWide(stairs);
  const auto d = Degrees(thin);
  EXPECT_EQ(std::count(d.begin(), d.end(), 1), 2);
  EXPECT_EQ(std::count(d.begin(), d.end(), 2), static_cast<long>(d.size()) - 2);
  EXPECT_EQ(CountComponents(thin), 1);
}

TEST(MakeOnePixelWide, TJunctionsAreClustersOrNotches) {
  cv::Mat t = cv::Mat::zeros(15, 15, CV_8UC1);
  cv::line(t, {5, 1}, {5, 13}, 255);
  cv::line(t, {6, 7}, {13, 7}, 255);
  const cv::Mat kept = MakeOnePixelWide(t, TJunctionShape::kCentreKept);
  EXPECT_EQ(cv::countNonZero(kept != t), 0);  // nothing to remove: the centre (5,7) stays
  EXPECT_EQ(Degree(kept, 5, 7), 3);
  const cv::Mat notched = MakeOnePixelWide(t, TJunctionShape::kNotched);
  EXPECT_EQ(notched.at<unsigned char>(7, 5), 0);
  const auto d = Degrees(notched);
  EXPECT_EQ(std::count_if(d.begin(), d.end(), [](int k) { return k >= 3; }), 1);
  EXPECT_EQ(Degree(notched, 6, 7), 3);
  EXPECT_EQ(CountComponents(notched), 1);
}

TEST(LineFollowing, PairsTheTwoFlankEdgesOfAStripeAndFollowsItsBranch) {
  // An edge image as Canny gives it: both flanks of a 5 px line (x = 8, 12)
  // and of a branch (y = 9, 13) leaving it to the right.
  cv::Mat e = cv::Mat::zeros(24, 30, CV_8UC1);
  cv::line(e, {8, 1}, {8, 22}, 255);
  cv::line(e, {12, 1}, {12, 9}, 255);
  cv::line(e, {12, 13}, {12, 22}, 255);
  cv::line(e, {12, 9}, {25, 9}, 255);
  cv::line(e, {12, 13}, {25, 13}, 255);
  LineFollowingParams p;
  p.bridge_gap = 3;
  const cv::Mat s = MakeOnePixelWide(LineFollowingThin(e, p));
  EXPECT_EQ(CountComponents(s), 1);
  for (int y = 2; y <= 21; ++y) EXPECT_EQ(s.at<unsigned char>(y, 10), 255) << "row " << y;
  for (int x = 14; x <= 24; ++x) EXPECT_EQ(s.at<unsigned char>(11, x), 255) << "column " << x;
}

TEST(LineFollowing, BridgesShortHolesAndSplitsLongForks) {
  // A 5 px line with a 3-row hole in its middle: still one line.
  cv::Mat hole = BinaryBar({30, 40}, 10, 5, 2, 37);
  hole(cv::Rect(12, 18, 1, 3)).setTo(0);
  const cv::Mat a = MakeOnePixelWide(LineFollowingThin(hole, {}));
  EXPECT_EQ(CountComponents(a), 1);
  // A fork: one line splitting into two 9 px apart for 15 rows.
  cv::Mat fork = BinaryBar({40, 50}, 16, 3, 2, 20);
  cv::line(fork, {17, 20}, {12, 30}, 255, 3);
  cv::line(fork, {17, 20}, {24, 30}, 255, 3);
  fork(cv::Rect(9, 30, 3, 15)).setTo(255);
  fork(cv::Rect(23, 30, 3, 15)).setTo(255);
  const cv::Mat b = MakeOnePixelWide(LineFollowingThin(fork, {}));
  EXPECT_EQ(CountComponents(b), 1);
  EXPECT_EQ(cv::countNonZero(b.row(40)), 2);  // both prongs
}

TEST(Thinning, InvalidInputsGiveTheDocumentedError) {
  const cv::Mat empty;
  const cv::Mat colour(8, 8, CV_8UC3, cv::Scalar::all(1));
  const cv::Mat wide(8, 8, CV_16UC1, cv::Scalar(1));
  for (const cv::Mat* bad : {&empty, &colour, &wide}) {
    ExpectInvalid([&] { ZhangSuenThin(*bad); }, "ZhangSuenThin");
    ExpectInvalid([&] { LineFollowingThin(*bad, {}); }, "LineFollowingThin");
    ExpectInvalid([&] { MakeOnePixelWide(*bad); }, "MakeOnePixelWide");
  }
  const cv::Mat ok(8, 8, CV_8UC1, cv::Scalar(0));
  LineFollowingParams bad;
  bad.margin = 0;
  ExpectInvalid([&] { LineFollowingThin(ok, bad); }, "LineFollowingThin");
}

}  // namespace
}  // namespace bsls::extraction
