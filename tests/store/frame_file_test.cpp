// Frame files (binary PGM) and pixel hashes: names, header, strict parsing,
// atomic write leaving no temporary file, SHA-256 against a known digest.
#include "bsls/store/frame_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "bsls/store/faulty_file_system.h"
#include "bsls/store/sha256.h"
#include "store_test_util.h"

namespace bsls::store {
namespace {

using framestore::Camera;
using testing::RandomFrame;
using testing::TempDir;

const CaptureId kId = *CaptureId::Parse("0190aabbccddeeff0011223344556677");

TEST(Sha256Test, PixelDigestIsStrideIndependent) {
  framestore::GreyFrame packed;
  packed.width = 3;
  packed.height = 1;
  packed.stride = 3;
  packed.pixels = {'a', 'b', 'c'};
  framestore::GreyFrame padded = packed;
  padded.stride = 5;
  padded.pixels = {'a', 'b', 'c', 'x', 'y'};
  EXPECT_EQ(PixelSha256(packed).value(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(PixelSha256(packed).value(), PixelSha256(padded).value());
  EXPECT_EQ(BytesSha256("abc").value(), PixelSha256(packed).value());
}

// A frame whose pixels are fewer than stride * height, or whose sides or
// stride make no frame, is refused with kInvalidArgument, not read past its
// end (the check was an assert, which Release compiles out).
TEST(Sha256Test, AMalformedFrameIsRefused) {
  framestore::GreyFrame frame;
  frame.width = 4;
  frame.height = 3;
  frame.stride = 5;
  frame.pixels.assign(14, 0);  // 15 needed
  Result<std::string> short_frame = PixelSha256(frame);
  ASSERT_FALSE(short_frame.ok());
  EXPECT_EQ(short_frame.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(short_frame.status().message().find("14 bytes"), std::string::npos)
      << short_frame.status().message();
  frame.pixels.assign(15, 0);
  EXPECT_TRUE(PixelSha256(frame).ok());
  frame.stride = 3;  // below the width
  EXPECT_EQ(PixelSha256(frame).status().code(), ErrorCode::kInvalidArgument);
  frame.stride = 5;
  frame.height = 0;
  EXPECT_EQ(PixelSha256(frame).status().code(), ErrorCode::kInvalidArgument);
}

TEST(FrameFileTest, NamesRoundTrip) {
  const std::string name = FrameFileName(kId, Camera::kRight);
  EXPECT_EQ(name, "0190aabbccddeeff0011223344556677-right.pgm");
  auto parts = ParseFrameFileName(name);
  ASSERT_TRUE(parts);
  EXPECT_EQ(parts->id, kId);
  EXPECT_EQ(parts->camera, Camera::kRight);
  EXPECT_FALSE(ParseFrameFileName(".tmp-" + name));
  EXPECT_FALSE(ParseFrameFileName("0190aabbccddeeff0011223344556677-fourth.pgm"));
  EXPECT_FALSE(ParseFrameFileName("notes.txt"));
}

TEST(FrameFileTest, WriteThenReadIsExactAndLeavesNoTemporaryFile) {
  TempDir dir;
  auto fs = MakePosixFileSystem();
  std::mt19937 rng(1);
  const framestore::GreyFrame frame = RandomFrame(rng, Camera::kLeft, 33, 17, 40);
  const std::string name = FrameFileName(kId, Camera::kLeft);
  auto bytes = WriteFrameFile(*fs, dir.path(), name, kId, frame);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  EXPECT_EQ(*bytes, FrameFileBytes(kId, Camera::kLeft, 33, 17));
  EXPECT_EQ(std::filesystem::file_size(dir.path() + "/" + name), *bytes);
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/.tmp-" + name));

  auto content = ReadFrameFile(*fs, dir.path() + "/" + name);
  ASSERT_TRUE(content.ok()) << content.status().ToString();
  EXPECT_EQ(content->width, 33);
  EXPECT_EQ(content->height, 17);
  ASSERT_EQ(content->pixels.size(), 33u * 17u);
  for (int y = 0; y < 17; ++y) {
    for (int x = 0; x < 33; ++x) ASSERT_EQ(content->pixels[y * 33 + x], frame.at(x, y));
  }
  // The header is what the format promises (any PGM viewer reads it).
  std::ifstream file(dir.path() + "/" + name, std::ios::binary);
  std::string magic, comment;
  std::getline(file, magic);
  std::getline(file, comment);
  EXPECT_EQ(magic, "P5");
  EXPECT_EQ(comment, "# bsls-frame 1 capture=" + kId.str() + " camera=left");
}

TEST(FrameFileTest, MalformedFilesAreDataLoss) {
  TempDir dir;
  auto fs = MakePosixFileSystem();
  auto write = [&](const std::string& text) {
    std::ofstream(dir.path() + "/f.pgm", std::ios::binary) << text;
    return ReadFrameFile(*fs, dir.path() + "/f.pgm").status().code();
  };
  EXPECT_EQ(write("P5\n2 2\n255\nabcd"), ErrorCode::kOk);
  EXPECT_EQ(write("P5\n2 2\n255\nabc"), ErrorCode::kDataLoss);     // truncated
  EXPECT_EQ(write("P5\n2 2\n255\nabcde"), ErrorCode::kDataLoss);   // trailing bytes
  EXPECT_EQ(write("P6\n2 2\n255\nabcd"), ErrorCode::kDataLoss);    // colour
  EXPECT_EQ(write("P5\n2 2\n65535\nabcd"), ErrorCode::kDataLoss);  // 16-bit
  EXPECT_EQ(write("P5\n-2 2\n255\nabcd"), ErrorCode::kDataLoss);
  EXPECT_EQ(write(""), ErrorCode::kDataLoss);
  EXPECT_EQ(ReadFrameFile(*fs, dir.path() + "/absent.pgm").status().code(), ErrorCode::kNotFound);
}

TEST(FrameFileTest, FailedWriteRemovesTheTemporaryFile) {
  TempDir dir;
  auto posix = MakePosixFileSystem();
  FaultyFileSystem fs(*posix);
  std::mt19937 rng(2);
  const framestore::GreyFrame frame = RandomFrame(rng, Camera::kLeft);
  for (FsOp op : {FsOp::kWrite, FsOp::kFsync, FsOp::kClose, FsOp::kRename}) {
    fs.FailNth(op, 1, Fault::kEio);
    auto bytes = WriteFrameFile(fs, dir.path(), "x.pgm", kId, frame);
    fs.Disarm();
    EXPECT_EQ(bytes.status().code(), ErrorCode::kUnavailable) << ToString(op);
    EXPECT_NE(bytes.status().message().find(".tmp-x.pgm"), std::string::npos)
        << bytes.status().message();
    EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << ToString(op);
  }
}

}  // namespace
}  // namespace bsls::store
