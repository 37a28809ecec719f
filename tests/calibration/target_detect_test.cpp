#include "bsls/calibration/target_detect.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "bsls/calibration/calibration_error.h"

namespace bsls::calibration {
namespace {

// Synthetic targets are drawn this many times larger, then area-averaged.
constexpr int kSupersample = 8;
constexpr double kNoiseSigma = 2.0;             // grey levels
constexpr double kCentreRmsTolerancePx = 0.05;  // drawn exactly: only noise and pixels
constexpr double kCentreMaxTolerancePx = 0.15;

// A target drawn through an affine map: grid point (col, row) in pitches
// lands at origin + col * along_col + row * along_row (pixels).
struct Drawing {
  int width = 512;
  int height = 512;
  int rows = 8;
  int cols = 8;
  double square = 0.6;  // side in pitches
  cv::Point2d origin{180.5, 150.25};
  cv::Point2d along_col{14.0, 0.0};
  cv::Point2d along_row{0.0, 15.0};
  double white = 230.0;
  double black = 25.0;
  double noise = kNoiseSigma;
  unsigned seed = 1;
  std::vector<cv::Point2i> skip;  // (col, row) squares left out
  int shifted_row = -1;           // this row is moved along the columns ...
  double shift = 0.0;             // ... by this many pitches

  cv::Point2d At(double col, double row) const {
    return origin + col * along_col + row * along_row;
  }
};

// The image and the centre of every drawn square, row-major (of the pixels
// actually filled, so that drawing does not count as detection error).
struct Drawn {
  cv::Mat image;
  std::vector<cv::Point2d> centres;
};

// Draws white ground and dark parallelograms (area coverage to
// 1 / kSupersample px), blurs by 0.5 px and adds Gaussian noise.
Drawn Draw(const Drawing& d) {
  cv::Mat big(d.height * kSupersample, d.width * kSupersample, CV_8UC1, cv::Scalar(255));
  const cv::Rect canvas(0, 0, big.cols, big.rows);
  Drawn out;
  for (int r = 0; r < d.rows; ++r) {
    for (int c = 0; c < d.cols; ++c) {
      const double col = c + (r == d.shifted_row ? d.shift : 0.0);
      // Low-res pixel centre x maps to high-res (x + 0.5) * k - 0.5.
      auto to_big = [](const cv::Point2d& p) {
        return (p + cv::Point2d(0.5, 0.5)) * kSupersample - cv::Point2d(0.5, 0.5);
      };
      auto to_small = [](const cv::Point2d& p) {
        return (p + cv::Point2d(0.5, 0.5)) * (1.0 / kSupersample) - cv::Point2d(0.5, 0.5);
      };
      out.centres.push_back(d.At(col, r));  // replaced by the drawn centre below
      if (std::find(d.skip.begin(), d.skip.end(), cv::Point2i(c, r)) != d.skip.end()) continue;
      std::vector<cv::Point2d> corners;
      for (const auto& [dc, dr] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}})
        corners.push_back(to_big(d.At(col + dc * d.square / 2, r + dr * d.square / 2)));
      std::vector<cv::Point2f> corners_f(corners.begin(), corners.end());
      const cv::Rect box = cv::boundingRect(corners_f) + cv::Size(2, 2) - cv::Point(1, 1);
      cv::Mat mask(box.size(), CV_8UC1, cv::Scalar(0));
      constexpr int kShift = 4;  // fixed-point bits of the vertices
      std::vector<cv::Point> fixed;
      for (const cv::Point2d& p : corners)
        fixed.emplace_back(static_cast<int>(std::lround((p.x - box.x) * (1 << kShift))),
                           static_cast<int>(std::lround((p.y - box.y) * (1 << kShift))));
      cv::fillConvexPoly(mask, fixed, cv::Scalar(255), cv::LINE_8, kShift);
      const cv::Moments m = cv::moments(mask, true);
      out.centres.back() = to_small({box.x + m.m10 / m.m00, box.y + m.m01 / m.m00});
      const cv::Rect visible = box & canvas;
      big(visible).setTo(0, mask(visible - box.tl()));
    }
  }
  cv::Mat coverage;  // 255 = white, 0 = dark
  cv::resize(big, coverage, cv::Size(d.width, d.height), 0, 0, cv::INTER_AREA);
  cv::Mat grey;
  coverage.convertTo(grey, CV_32F, (d.white - d.black) / 255.0, d.black);
  cv::GaussianBlur(grey, grey, cv::Size(0, 0), 0.5);
  if (d.noise > 0) {
    std::mt19937 rng(d.seed);
    std::normal_distribution<float> noise(0.0f, static_cast<float>(d.noise));
    for (int y = 0; y < grey.rows; ++y)
      for (float* p = grey.ptr<float>(y); p != grey.ptr<float>(y) + grey.cols; ++p)
        *p += noise(rng);
  }
  grey.convertTo(out.image, CV_8UC1);
  return out;
}

TargetGeometry Grid(int rows, int cols) {
  TargetGeometry target;
  target.rows = rows;
  target.cols = cols;
  return target;
}

// Every square at (row, col) with its centre within the tolerances.
void ExpectGrid(const TargetDetection& detection, const Drawn& drawn, int rows, int cols) {
  ASSERT_TRUE(detection.ok) << detection.error;
  ASSERT_EQ(detection.squares.size(), static_cast<size_t>(rows * cols));
  double sum2 = 0.0, worst = 0.0;
  for (int i = 0; i < rows * cols; ++i) {
    const TargetSquare& s = detection.squares[i];
    EXPECT_EQ(s.row, i / cols);
    EXPECT_EQ(s.col, i % cols);
    const double error = cv::norm(s.centre - drawn.centres[i]);
    sum2 += error * error;
    worst = std::max(worst, error);
  }
  EXPECT_LT(std::sqrt(sum2 / (rows * cols)), kCentreRmsTolerancePx);
  EXPECT_LT(worst, kCentreMaxTolerancePx);
}

TEST(DetectTarget, FindsAxisAlignedGridWithSubPixelCentres) {
  const Drawn drawn = Draw({});
  ExpectGrid(DetectTarget(drawn.image, Grid(8, 8)), drawn, 8, 8);
}

TEST(DetectTarget, OrdersRotatedAndShearedGridFromTheImageTopLeft) {
  Drawing d;
  const double angle = 25.0 * CV_PI / 180.0;  // clockwise in the image (y down)
  d.along_col = {13.0 * std::cos(angle), 13.0 * std::sin(angle)};
  d.along_row = {-16.0 * std::sin(angle) + 2.0, 16.0 * std::cos(angle)};
  d.origin = {230.0, 120.0};
  d.seed = 2;
  const Drawn drawn = Draw(d);
  const TargetDetection detection = DetectTarget(drawn.image, Grid(8, 8));
  ExpectGrid(detection, drawn, 8, 8);
  EXPECT_LT(detection.max_grid_residual, 0.05);
}

TEST(DetectTarget, RotatedTheOtherWayStillStartsTopLeft) {
  Drawing d;
  const double angle = -30.0 * CV_PI / 180.0;
  d.along_col = {14.0 * std::cos(angle), 14.0 * std::sin(angle)};
  d.along_row = {-14.0 * std::sin(angle), 14.0 * std::cos(angle)};
  d.origin = {150.0, 250.0};
  d.seed = 3;
  const Drawn drawn = Draw(d);
  ExpectGrid(DetectTarget(drawn.image, Grid(8, 8)), drawn, 8, 8);
}

TEST(DetectTarget, NonSquareGridKeepsRowsAndColumnsApart) {
  Drawing d;
  d.rows = 5;
  d.cols = 9;
  d.seed = 4;
  const Drawn drawn = Draw(d);
  ExpectGrid(DetectTarget(drawn.image, Grid(5, 9)), drawn, 5, 9);
  // The same image is not a 9 x 5 target.
  const TargetDetection wrong = DetectTarget(drawn.image, Grid(9, 5));
  EXPECT_FALSE(wrong.ok);
  EXPECT_NE(wrong.error.find("do not form a 9 x 5 grid"), std::string::npos) << wrong.error;
}

TEST(DetectTarget, PerspectiveGridIsOrdered) {
  // A trapezoid: the far rows narrower, as seen by an oblique camera.
  Drawing d;
  d.seed = 5;
  Drawn drawn = Draw(d);  // for the image size only
  std::vector<cv::Point2f> from = {{100, 100}, {400, 100}, {400, 400}, {100, 400}};
  std::vector<cv::Point2f> to = {{140, 110}, {370, 120}, {420, 400}, {90, 390}};
  const cv::Mat h = cv::getPerspectiveTransform(from, to);
  cv::Mat warped;
  cv::warpPerspective(drawn.image, warped, h, drawn.image.size(), cv::INTER_CUBIC,
                      cv::BORDER_REPLICATE);
  std::vector<cv::Point2d> moved;
  cv::perspectiveTransform(drawn.centres, moved, h);
  const TargetDetection detection = DetectTarget(warped, Grid(8, 8));
  ASSERT_TRUE(detection.ok) << detection.error;
  for (int i = 0; i < 64; ++i) {
    EXPECT_EQ(detection.squares[i].row, i / 8);
    EXPECT_EQ(detection.squares[i].col, i % 8);
    // Centre of gravity vs mapped centre: perspective moves them apart a little.
    EXPECT_LT(cv::norm(detection.squares[i].centre - moved[i]), 0.2) << i;
  }
}

TEST(DetectTarget, MissingSquareIsReportedNotGuessed) {
  Drawing d;
  d.skip = {{3, 4}};
  const TargetDetection detection = DetectTarget(Draw(d).image, Grid(8, 8));
  EXPECT_FALSE(detection.ok);
  EXPECT_TRUE(detection.squares.empty());
  EXPECT_NE(detection.error.find("found 63 of 64 target squares"), std::string::npos)
      << detection.error;
}

TEST(DetectTarget, GridCutByTheImageBorderIsReported) {
  Drawing d;
  d.origin = {415.5, 150.0};  // column 7 is cut by the right border
  const TargetDetection detection = DetectTarget(Draw(d).image, Grid(8, 8));
  EXPECT_FALSE(detection.ok);
  EXPECT_NE(detection.error.find(" of 64 target squares"), std::string::npos) << detection.error;
  EXPECT_NE(detection.error.find("cut by the image border"), std::string::npos) << detection.error;
}

TEST(DetectTarget, ExtraSquareBesideTheGridIsReported) {
  Drawing d;
  Drawn drawn = Draw(d);
  const cv::Point2d extra = d.At(8, 3);  // one more column, one square only
  cv::rectangle(drawn.image, cv::Rect(cv::Point(extra) - cv::Point(4, 4), cv::Size(9, 9)),
                cv::Scalar(25), cv::FILLED);
  const TargetDetection detection = DetectTarget(drawn.image, Grid(8, 8));
  EXPECT_FALSE(detection.ok);
  EXPECT_NE(detection.error.find("found 65 square-like blobs"), std::string::npos)
      << detection.error;
}

TEST(DetectTarget, ClutterAwayFromTheGridIsIgnored) {
  Drawing d;
  Drawn drawn = Draw(d);
  // A square far from the grid, a long bar and a disc of another size.
  cv::rectangle(drawn.image, cv::Rect(40, 420, 9, 9), cv::Scalar(25), cv::FILLED);
  cv::rectangle(drawn.image, cv::Rect(40, 40, 80, 6), cv::Scalar(25), cv::FILLED);
  cv::circle(drawn.image, cv::Point(450, 450), 20, cv::Scalar(25), cv::FILLED);
  ExpectGrid(DetectTarget(drawn.image, Grid(8, 8)), drawn, 8, 8);
}

TEST(DetectTarget, SquaresNotOnAGridAreUnorderable) {
  Drawing d;
  d.shifted_row = 7;  // the bottom row half a pitch to the right
  d.shift = 0.5;
  const TargetDetection detection = DetectTarget(Draw(d).image, Grid(8, 8));
  EXPECT_FALSE(detection.ok);
  EXPECT_TRUE(detection.squares.empty());
  EXPECT_NE(detection.error.find("do not form a 8 x 8 grid"), std::string::npos) << detection.error;
}

TEST(DetectTarget, BlankImageFindsNothing) {
  const cv::Mat blank(256, 256, CV_8UC1, cv::Scalar(200));
  const TargetDetection detection = DetectTarget(blank, Grid(8, 8));
  EXPECT_FALSE(detection.ok);
  EXPECT_NE(detection.error.find("found 0 of 64"), std::string::npos) << detection.error;
}

TEST(DetectTarget, InvalidInputOrParamsThrow) {
  const cv::Mat colour(64, 64, CV_8UC3, cv::Scalar::all(128));
  try {
    DetectTarget(colour, Grid(8, 8));
    FAIL() << "a colour image was accepted";
  } catch (const CalibrationError& e) {
    EXPECT_EQ(e.reason(), CalibrationErrorReason::kInvalidInput);
  }
  EXPECT_THROW(DetectTarget(cv::Mat(), Grid(8, 8)), CalibrationError);
  TargetDetectParams params;
  params.threshold_block_px = 50;  // even
  std::string why;
  EXPECT_FALSE(params.IsValid(&why));
  EXPECT_NE(why.find("threshold_block_px"), std::string::npos);
  try {
    DetectTarget(cv::Mat(64, 64, CV_8UC1, cv::Scalar(0)), Grid(8, 8), params);
    FAIL() << "invalid params were accepted";
  } catch (const CalibrationError& e) {
    EXPECT_EQ(e.reason(), CalibrationErrorReason::kInvalidParams);
  }
  EXPECT_THROW(DetectTarget(cv::Mat(64, 64, CV_8UC1, cv::Scalar(0)), Grid(1, 8)), CalibrationError);
}

}  // namespace
}  // namespace bsls::calibration
