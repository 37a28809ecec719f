// Frames read from image files: the size limits hold before anything is
// decoded (a PNG that claims a huge size allocates nothing for it).
#include "bsls/io/frame_file.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace bsls::io {
namespace {

std::vector<unsigned char> Png(const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes));
  return bytes;
}

// Writes `value` big-endian at `at`.
void PutBe32(std::vector<unsigned char>* bytes, size_t at, std::uint32_t value) {
  for (int k = 0; k < 4; ++k) (*bytes)[at + k] = static_cast<unsigned char>(value >> (24 - 8 * k));
}

TEST(FrameFile, APngWithinTheLimitsIsRead) {
  cv::Mat image(64, 80, CV_8UC1, cv::Scalar(7));
  const cv::Mat grey = DecodeGreyFrame(Png(image), "small.png");
  EXPECT_EQ(grey.cols, 80);
  EXPECT_EQ(grey.rows, 64);
  EXPECT_EQ(cv::countNonZero(grey != 7), 0);
}

TEST(FrameFile, APngClaimingAHugeSizeIsRefusedFromItsHeader) {
  // A real PNG whose header is changed to claim 200000 x 200000 pixels
  // (40 GB as 8-bit grey); its CRC no longer matches, so only a check of
  // the header can name the size.
  std::vector<unsigned char> bytes = Png(cv::Mat(32, 32, CV_8UC1, cv::Scalar(0)));
  PutBe32(&bytes, 16, 200000);
  PutBe32(&bytes, 20, 200000);
  try {
    (void)DecodeGreyFrame(bytes, "bomb.png");
    FAIL() << "a PNG claiming 200000 x 200000 was decoded";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bomb.png"), std::string::npos) << what;
    EXPECT_NE(what.find("200000x200000"), std::string::npos) << what;
  }
}

TEST(FrameFile, LimitsAreTheCallersOwn) {
  const std::vector<unsigned char> bytes = Png(cv::Mat(600, 600, CV_8UC1, cv::Scalar(1)));
  FrameLimits limits;
  limits.max_side = 512;
  EXPECT_THROW((void)DecodeGreyFrame(bytes, "big.png", nullptr, limits), InputError);
  limits.max_side = 600;
  EXPECT_EQ(DecodeGreyFrame(bytes, "big.png", nullptr, limits).cols, 600);
}

// Issue 26: sides within max_side (16384) still allowed 268 Mpx, 2 GiB
// allocated for a 16-bit RGBA header; bsls-processd read calibration images
// up to that size whatever its frame budget. The pixel count is a limit of
// its own, checked on the header too.
TEST(FrameFile, APngAboveThePixelBudgetIsRefusedFromItsHeader) {
  std::vector<unsigned char> bytes = Png(cv::Mat(32, 32, CV_8UC1, cv::Scalar(0)));
  PutBe32(&bytes, 16, 16384);
  PutBe32(&bytes, 20, 16384);
  try {
    (void)DecodeGreyFrame(bytes, "wide.png");
    FAIL() << "a PNG claiming 16384 x 16384 was decoded";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("wide.png: size 16384x16384 = 268435456 pixels is above the budget of "
                        "16777216"),
              std::string::npos)
        << what;
  }
  const std::vector<unsigned char> real = Png(cv::Mat(300, 300, CV_8UC1, cv::Scalar(1)));
  FrameLimits limits;
  limits.max_pixels = 300 * 300 - 1;
  EXPECT_THROW((void)DecodeGreyFrame(real, "real.png", nullptr, limits), InputError);
  limits.max_pixels = 300 * 300;
  EXPECT_EQ(DecodeGreyFrame(real, "real.png", nullptr, limits).total(), 300u * 300u);
}

}  // namespace
}  // namespace bsls::io
