#include "bsls/extraction/pruning.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "expect_invalid.h"
#include "synthetic_images.h"

namespace bsls::extraction {
namespace {

using testing::CountComponents;
using testing::ExpectInvalid;

TEST(PruningWindows, EraseSpecksWhoseRingIsEmpty) {
  cv::Mat img = cv::Mat::zeros(30, 30, CV_8UC1);
  cv::line(img, {2, 2}, {2, 27}, 255);    // a line: stays
  img.at<unsigned char>(5, 10) = 255;     // 1x1
  img(cv::Rect(15, 5, 2, 1)).setTo(255);  // 1x2 horizontal
  img(cv::Rect(22, 5, 1, 2)).setTo(255);  // 2x1 vertical
  img.at<unsigned char>(12, 10) = 255;    // diagonal pair in a 2x2 box
  img.at<unsigned char>(13, 11) = 255;
  img.at<unsigned char>(12, 21) = 255;  // the other diagonal
  img.at<unsigned char>(13, 20) = 255;
  img(cv::Rect(15, 20, 2, 2)).setTo(255);  // 2x2 block
  img(cv::Rect(22, 20, 3, 3)).setTo(255);  // 3x3: too big for the thesis windows
  img.at<unsigned char>(10, 3) = 255;      // touches the line: its ring is not empty
  const cv::Mat out = ApplyPruningWindows(img);
  EXPECT_EQ(cv::countNonZero(out.col(2)), 26);
  EXPECT_EQ(out.at<unsigned char>(10, 3), 255);
  EXPECT_EQ(cv::countNonZero(out(cv::Rect(5, 3, 20, 12))), 0);
  EXPECT_EQ(cv::countNonZero(out(cv::Rect(14, 19, 4, 4))), 0);
  EXPECT_EQ(cv::countNonZero(out(cv::Rect(22, 20, 3, 3))), 9);
  PruningWindowParams bigger;
  bigger.max_interior = 3;
  EXPECT_EQ(cv::countNonZero(ApplyPruningWindows(img, bigger)(cv::Rect(22, 20, 3, 3))), 0);
}

// A vertical line x = 10, y = 2..37 with a branch to the right at row 20 of
// `branch` pixels.
cv::Mat LineWithBranch(int branch) {
  cv::Mat img = cv::Mat::zeros(40, 40, CV_8UC1);
  cv::line(img, {10, 2}, {10, 37}, 255);
  if (branch > 0) cv::line(img, {11, 20}, {10 + branch, 20}, 255);
  return img;
}

TEST(PruneSpurs, RemovesShortBranchesOffAJunction) {
  SpurPruneParams p;
  p.max_spur_length = 6;
  const cv::Mat spur = PruneSpurs(LineWithBranch(3), p);
  EXPECT_EQ(cv::countNonZero(spur), 36);  // the line alone, full length
  EXPECT_EQ(cv::countNonZero(spur.col(10)), 36);
  const cv::Mat branch = PruneSpurs(LineWithBranch(12), p);
  EXPECT_EQ(cv::countNonZero(branch), 36 + 12);  // a real branch stays
}

TEST(PruneSpurs, FreeLineEndsAreKeptUnlessAskedOtherwise) {
  cv::Mat img = cv::Mat::zeros(20, 40, CV_8UC1);
  cv::line(img, {2, 5}, {30, 5}, 255);   // a free line of 29 px
  cv::line(img, {2, 12}, {5, 12}, 255);  // a free line of 4 px
  SpurPruneParams p;
  p.max_spur_length = 6;
  EXPECT_EQ(cv::countNonZero(PruneSpurs(img, p)), 29 + 4);
  p.keep_free_ends = false;
  EXPECT_EQ(cv::countNonZero(PruneSpurs(img, p)), 29);
}

TEST(PruneSpurs, OfTwoShortProngsAtALineEndOnlyTheShorterGoes) {
  cv::Mat img = cv::Mat::zeros(40, 40, CV_8UC1);
  cv::line(img, {20, 2}, {20, 25}, 255);
  cv::line(img, {21, 26}, {24, 29}, 255);  // 4 px prong
  cv::line(img, {19, 26}, {18, 27}, 255);  // 2 px prong
  SpurPruneParams p;
  p.max_spur_length = 6;
  const cv::Mat out = PruneSpurs(img, p);
  EXPECT_EQ(out.at<unsigned char>(29, 24), 255);
  EXPECT_EQ(out.at<unsigned char>(27, 18), 0);
  EXPECT_EQ(CountComponents(out), 1);
}

TEST(RemoveSmallComponents, DropsComponentsBelowTheSize) {
  cv::Mat img = cv::Mat::zeros(20, 20, CV_8UC1);
  cv::line(img, {1, 1}, {10, 1}, 255);  // 10 px
  cv::line(img, {1, 5}, {3, 5}, 255);   // 3 px
  EXPECT_EQ(cv::countNonZero(RemoveSmallComponents(img, 4)), 10);
  EXPECT_EQ(cv::countNonZero(RemoveSmallComponents(img, 1)), 13);
}

TEST(Pruning, InvalidInputsGiveTheDocumentedError) {
  const cv::Mat empty;
  const cv::Mat colour(8, 8, CV_8UC3, cv::Scalar::all(1));
  const cv::Mat wide(8, 8, CV_16UC1, cv::Scalar(1));
  for (const cv::Mat* bad : {&empty, &colour, &wide}) {
    ExpectInvalid([&] { ApplyPruningWindows(*bad); }, "ApplyPruningWindows");
    ExpectInvalid([&] { PruneSpurs(*bad); }, "PruneSpurs");
    ExpectInvalid([&] { RemoveSmallComponents(*bad, 3); }, "RemoveSmallComponents");
  }
  const cv::Mat ok(8, 8, CV_8UC1, cv::Scalar(0));
  ExpectInvalid([&] { RemoveSmallComponents(ok, 0); }, "RemoveSmallComponents");
  SpurPruneParams bad;
  bad.max_spur_length = 0;
  ExpectInvalid([&] { PruneSpurs(ok, bad); }, "PruneSpurs");
}

}  // namespace
}  // namespace bsls::extraction
