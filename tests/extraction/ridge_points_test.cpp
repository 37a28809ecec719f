#include "bsls/extraction/ridge_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bsls/extraction/stripe_centre.h"
#include "expect_invalid.h"
#include "synthetic_images.h"

namespace bsls::extraction {
namespace {

using testing::ExpectInvalid;
using testing::RenderSlantedStripe;
using testing::RenderStripeProfile;

constexpr double kPeakTolerance = 0.5;    // px: a ridge point's parabola against the true centre
constexpr double kCentreTolerance = 0.1;  // px: RidgeCentreInRow without noise

cv::Mat Smoothed(const cv::Mat& grey) {
  cv::Mat s;
  cv::GaussianBlur(grey, s, cv::Size(0, 0), 1.0, 1.0, cv::BORDER_REPLICATE);
  return s;
}

// Vertical stripes of `width` px at the given centres, every row alike.
cv::Mat VerticalStripes(cv::Size size, const std::vector<double>& centres, double width,
                        double contrast = 150.0) {
  cv::Mat img(size, CV_8UC1, cv::Scalar(20));
  for (double c : centres) {
    const std::vector<double> row = RenderStripeProfile(size.width, c, width, 0.8, 0.0, contrast);
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x)
        img.at<uchar>(y, x) = cv::saturate_cast<uchar>(img.at<uchar>(y, x) + row[x]);
  }
  return img;
}

TEST(RidgePoints, EveryStripeOncePerRowAtItsCentre) {
  const std::vector<double> centres = {30.3, 51.8, 70.5, 92.1};
  for (const double width : {1.0, 2.0, 4.0, 7.0}) {
    const cv::Mat img = VerticalStripes({128, 40}, centres, width);
    const RidgePoints found = FindRidgePoints(Smoothed(img));
    ASSERT_EQ(found.row_start.size(), 41u);
    for (int y = 0; y < img.rows; ++y) {
      const auto row = found.Row(y);
      ASSERT_EQ(row.size(), centres.size()) << "width " << width << " row " << y;
      for (size_t i = 0; i < centres.size(); ++i) {
        EXPECT_NEAR(row[i].x, centres[i], kPeakTolerance) << "width " << width;
        EXPECT_EQ(row[i].y, y);
        EXPECT_GE(row[i].prominence, RidgeParams{}.min_prominence);
      }
    }
  }
}

TEST(RidgePoints, ASegmentAlongTheRowIsNoRidgeOfItButOfTheColumns) {
  // A horizontal band: flat along the rows it covers, a peak down each column.
  cv::Mat img(64, 96, CV_8UC1, cv::Scalar(20));
  const std::vector<double> profile = RenderStripeProfile(64, 31.4, 2.5, 0.8, 0.0, 150.0);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 20; x < 76; ++x) img.at<uchar>(y, x) = cv::saturate_cast<uchar>(20 + profile[y]);
  const cv::Mat s = Smoothed(img);
  const RidgePoints rows = FindRidgePoints(s);
  for (int y = 25; y <= 38; ++y)
    for (const RidgePoint& p : rows.Row(y))
      EXPECT_TRUE(p.x < 20 || p.x > 75) << "a ridge point inside the band at row " << y;
  const RidgePoints columns = FindColumnRidgePoints(s);
  for (int x = 30; x < 66; ++x) {
    const auto column = columns.Row(x);
    ASSERT_EQ(column.size(), 1u) << "column " << x;
    EXPECT_NEAR(column[0].x, 31.4, kPeakTolerance);
    EXPECT_EQ(column[0].y, x);
  }
}

TEST(RidgePoints, ColumnsGiveWhatTheTransposedImageGivesAlongItsRows) {
  // A noisy brick scene, both directions, to the last bit; odd sizes leave a
  // last block of columns narrower than a vector.
  testing::BrickScene scene;
  scene.width = 203;
  scene.height = 157;
  testing::BrickTruth truth;
  const cv::Mat s = Smoothed(RenderBrickScene(scene, &truth));
  cv::Mat transposed;
  cv::transpose(s, transposed);
  for (const int window : {3, 8, 13}) {
    RidgeParams params;
    params.half_window = window;
    const RidgePoints direct = FindColumnRidgePoints(s, params);
    const RidgePoints via = FindRidgePoints(transposed, params);
    ASSERT_EQ(direct.points.size(), via.points.size()) << "window " << window;
    EXPECT_EQ(direct.row_start, via.row_start);
    for (size_t i = 0; i < direct.points.size(); ++i) {
      EXPECT_EQ(direct.points[i].x, via.points[i].x);
      EXPECT_EQ(direct.points[i].y, via.points[i].y);
      EXPECT_EQ(direct.points[i].prominence, via.points[i].prominence);
    }
  }
}

TEST(RidgePoints, AStripeCutByTheImageEdgeIsJudgedByItsInnerFlank) {
  // Peaks on the edge pixel and 2 px inside it, on both sides.
  const cv::Mat img = VerticalStripes({64, 8}, {0.0, 2.0, 61.0, 63.0}, 1.5);
  const cv::Mat s = Smoothed(img);
  const RidgePoints found = FindRidgePoints(s);
  const auto row = found.Row(4);
  bool left_edge = false, right_edge = false;
  for (const RidgePoint& p : row) {
    left_edge |= p.x <= 2.5;
    right_edge |= p.x >= 60.5;
  }
  EXPECT_TRUE(left_edge);
  EXPECT_TRUE(right_edge);
  // A broad hill (falling less than the prominence within the window) is no
  // ridge, neither at its top nor at the image's edges, which lie lower.
  cv::Mat hill(8, 64, CV_8UC1);
  for (int x = 0; x < 64; ++x)
    hill.col(x).setTo(cvRound(20 + 60 * std::exp(-(x - 32.0) * (x - 32.0) / 1800.0)));
  for (int y = 0; y < 8; ++y)
    for (const RidgePoint& p : FindRidgePoints(hill).Row(y))
      ADD_FAILURE() << "a ridge point on a broad hill at x " << p.x;
  // Light rising to the edge looks like a stripe cut there, and is taken so.
  cv::Mat ramp(8, 64, CV_8UC1);
  for (int x = 0; x < 64; ++x) ramp.col(x).setTo(100 - x);
  for (int y = 0; y < 8; ++y) {
    ASSERT_EQ(FindRidgePoints(ramp).Row(y).size(), 1u);
    EXPECT_EQ(FindRidgePoints(ramp).Row(y)[0].x, 0.0f);
  }
}

TEST(RidgePoints, AStripeFainterThanTheProminenceIsNotAPoint) {
  RidgeParams params;
  params.min_prominence = 10;
  const cv::Mat faint = VerticalStripes({64, 8}, {32.0}, 2.0, 8.0);
  const cv::Mat clear = VerticalStripes({64, 8}, {32.0}, 2.0, 40.0);
  EXPECT_TRUE(FindRidgePoints(Smoothed(faint), params).points.empty());
  EXPECT_EQ(FindRidgePoints(Smoothed(clear), params).points.size(), 8u);
}

TEST(RidgePoints, RidgeCentresAreSubPixelAlongRowsAndColumns) {
  for (const double width : {1.5, 3.0, 5.0}) {
    for (const double x0 : {40.0, 40.25, 40.5, 40.8}) {
      const cv::Mat img = RenderSlantedStripe({96, 24}, x0, 0.0, width, 0.8, 20, 150, 0.0, 1);
      const auto x = RidgeCentreInRow(img, 12, x0 + 1.4);
      ASSERT_TRUE(x.has_value()) << "width " << width << " x0 " << x0;
      EXPECT_NEAR(*x, x0, kCentreTolerance) << "width " << width;
      cv::Mat transposed;
      cv::transpose(img, transposed);
      const auto y = RidgeCentreInColumn(transposed, 12, x0 - 1.4);
      ASSERT_TRUE(y.has_value());
      EXPECT_EQ(*y, *x);  // the same arithmetic across the other axis
    }
  }
  // Nothing to measure: a flat image, the image's edges.
  const cv::Mat flat(32, 64, CV_8UC1, cv::Scalar(80));
  EXPECT_FALSE(RidgeCentreInRow(flat, 10, 30.0).has_value());
  const cv::Mat img = RenderSlantedStripe({64, 24}, 5.0, 0.0, 2.0, 0.8, 20, 150, 0.0, 1);
  EXPECT_FALSE(RidgeCentreInRow(img, 12, 5.0).has_value());
  EXPECT_FALSE(RidgeCentreInRow(img, 0, 30.0).has_value());
}

TEST(RidgePoints, InvalidInputsGiveTheDocumentedError) {
  const cv::Mat ok(16, 16, CV_8UC1, cv::Scalar(0));
  ExpectInvalid([] { FindRidgePoints(cv::Mat()); }, "FindRidgePoints");
  ExpectInvalid([] { FindRidgePoints(cv::Mat(8, 8, CV_32F)); }, "FindRidgePoints");
  ExpectInvalid([] { FindColumnRidgePoints(cv::Mat(8, 8, CV_16U)); }, "FindColumnRidgePoints");
  RidgeParams bad;
  bad.half_window = 0;
  ExpectInvalid([&] { FindRidgePoints(ok, bad); }, "FindRidgePoints");
  bad = {};
  bad.min_prominence = 256;
  ExpectInvalid([&] { FindColumnRidgePoints(ok, bad); }, "FindColumnRidgePoints");
}

}  // namespace
}  // namespace bsls::extraction
