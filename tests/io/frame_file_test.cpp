// Frames read from image files: the size limits hold before anything is
// decoded (a PNG that claims a huge size allocates nothing for it).
#include "bsls/io/frame_file.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "bsls/common/errors.h"

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

// The refusal's message for a real 32 x 32 PNG whose header is changed to
// claim `side` x `side` pixels and is read as `name`; its CRC no longer
// matches, so only a check of the header can name the size. Empty (and a
// failure) when it was decoded.
std::string RefusalOfAPngClaiming(std::uint32_t side, const std::string& name) {
  std::vector<unsigned char> bytes = Png(cv::Mat(32, 32, CV_8UC1, cv::Scalar(0)));
  PutBe32(&bytes, 16, side);
  PutBe32(&bytes, 20, side);
  try {
    (void)DecodeGreyFrame(bytes, name);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "a PNG claiming " << side << " x " << side << " was decoded";
  return "";
}

TEST(FrameFile, APngClaimingAHugeSizeIsRefusedFromItsHeader) {
  // 200000 x 200000 pixels: 40 GB as 8-bit grey.
  const std::string what = RefusalOfAPngClaiming(200000, "bomb.png");
  EXPECT_NE(what.find("bomb.png"), std::string::npos) << what;
  EXPECT_NE(what.find("200000x200000"), std::string::npos) << what;
}

TEST(FrameFile, LimitsAreTheCallersOwn) {
  const std::vector<unsigned char> bytes = Png(cv::Mat(600, 600, CV_8UC1, cv::Scalar(1)));
  FrameLimits limits;
  limits.max_side = 512;
  EXPECT_THROW((void)DecodeGreyFrame(bytes, "big.png", nullptr, limits), InputError);
  limits.max_side = 600;
  EXPECT_EQ(DecodeGreyFrame(bytes, "big.png", nullptr, limits).cols, 600);
}

// Sides within max_side (16384) would still allow 268 Mpx (2 GiB for a
// 16-bit RGBA header), whatever a service's frame budget: the pixel count
// is a limit of its own, checked on the header too.
TEST(FrameFile, APngAboveThePixelBudgetIsRefusedFromItsHeader) {
  const std::string what = RefusalOfAPngClaiming(16384, "wide.png");
  EXPECT_NE(what.find("wide.png: size 16384x16384 = 268435456 pixels is above the budget of "
                      "16777216"),
            std::string::npos)
      << what;
  const std::vector<unsigned char> real = Png(cv::Mat(300, 300, CV_8UC1, cv::Scalar(1)));
  FrameLimits limits;
  limits.max_pixels = 300 * 300 - 1;
  EXPECT_THROW((void)DecodeGreyFrame(real, "real.png", nullptr, limits), InputError);
  limits.max_pixels = 300 * 300;
  EXPECT_EQ(DecodeGreyFrame(real, "real.png", nullptr, limits).total(), 300u * 300u);
}

// Found by the PNG fuzz target (issue 26): cv::imdecode reads many formats,
// and its DICOM reader (GDCM) allocated 3.5 GB from a length field of a
// 200-byte input before any size check. Frames are PNG or PNM; everything
// else is refused before a decoder sees it, and PNM's size is checked from
// its header like PNG's.
TEST(FrameFile, OnlyPngAndPnmAreReadAndPnmSizesAreCheckedFirst) {
  std::vector<unsigned char> dicom(128, 0);
  for (const char c : std::string("DICM\x02\x00\x10\x00OB\x00\x00\xff\xff\xff\xd0"))
    dicom.push_back(static_cast<unsigned char>(c));
  for (const auto& [name, bytes] :
       {std::pair<std::string, std::vector<unsigned char>>{"dicom.dcm", dicom},
        {"j2k.jp2", {0x00, 0x00, 0x00, 0x0c, 'j', 'P', ' ', ' ', 0x0d, 0x0a, 0x87, 0x0a}},
        {"jpeg.jpg", {0xff, 0xd8, 0xff, 0xe0, 0x00, 0x10, 'J', 'F', 'I', 'F'}},
        {"pam.pam", {'P', '7', '\n'}}}) {
    try {
      (void)DecodeGreyFrame(bytes, name);
      ADD_FAILURE() << name << " was decoded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(name + ": not a PNG or PNM image"), std::string::npos)
          << e.what();
    }
  }
  // A PGM, as the capture store writes them, is read.
  std::string pgm = "P5\n# a comment\n20 16\n255\n" + std::string(20 * 16, '\x40');
  const cv::Mat grey = DecodeGreyFrame({pgm.begin(), pgm.end()}, "frame.pgm");
  EXPECT_EQ(grey.cols, 20);
  EXPECT_EQ(grey.rows, 16);
  // One claiming 100000 x 100000 is refused from its header.
  const std::string bomb = "P5 100000 100000 255\n" + std::string(64, '\0');
  try {
    (void)DecodeGreyFrame({bomb.begin(), bomb.end()}, "bomb.pgm");
    FAIL() << "a PGM claiming 100000 x 100000 was decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("100000x100000"), std::string::npos) << e.what();
  }
  const std::string no_size = "P5 # no size\n";
  EXPECT_THROW((void)DecodeGreyFrame({no_size.begin(), no_size.end()}, "x.pgm"), InputError);
}

}  // namespace
}  // namespace bsls::io
