#include "bsls/common/sha256.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "bsls/common/errors.h"

namespace bsls {
namespace {

// FIPS 180-2 test vectors.
TEST(Sha256, KnownVectors) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, BinaryBytesAndFilesAgree) {
  std::string bytes(1000, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7);
  const auto path = std::filesystem::path(::testing::TempDir()) / "digest_test.bin";
  std::ofstream(path, std::ios::binary) << bytes;
  EXPECT_EQ(Sha256OfFile(path.string()), Sha256Hex(bytes));
  EXPECT_NE(Sha256Hex(bytes), Sha256Hex(bytes.substr(1)));
  std::filesystem::remove(path);
}

TEST(Sha256, PiecesDigestAsTheWhole) {
  const std::string text = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  Sha256 digest;
  digest.Update(text.substr(0, 5));
  digest.Update(text.data() + 5, 0);
  digest.Update(text.substr(5));
  EXPECT_EQ(digest.HexDigest(), Sha256Hex(text));
  // Spent: a second digest is an error reported, not undefined behaviour.
  EXPECT_THROW(digest.HexDigest(), DigestError);
  EXPECT_THROW(digest.Update("more"), DigestError);
}

TEST(Sha256, MissingFileNamesIt) {
  try {
    Sha256OfFile("/nonexistent/manifest.yaml");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/manifest.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace bsls
